// The level of detail that both the instanced shader and culling per instance apply: far
// thinning and growth by rank, from a class's `Lod` (the chunk's uniform holds one, and so
// does each culling record).

#define_import_path rwt::fade

// A class's level of detail (`LodUniform`).
struct Lod {
    // The fall-off: near, far, the factor's floor; 1 when there is one.
    falloff_near: f32,
    falloff_far: f32,
    falloff_floor: f32,
    falloff_on: u32,
    // The band of ranks an instance grows over.
    fade_band: f32,
    // Far thinning: its distance, its floor; 1 when it is on.
    thinning_from: f32,
    thinning_floor: f32,
    thinning_on: u32,
};

// Far thinning at `root`, seen from `eye` (x, z): the fraction of instances kept there (1
// without thinning).
fn kept_fraction(lod: Lod, eye: vec2<f32>, root: vec3<f32>) -> f32 {
    let ratio = lod.thinning_from / max(length(root.xz - eye), 1e-3);
    let kept = clamp(ratio * ratio, lod.thinning_floor, 1.0);
    return select(1.0, kept, lod.thinning_on != 0u);
}

// Growth of an instance: 0 until the level-of-detail factor at its place reaches the one at
// which its point appears, then up to 1 over the fade band (always 1 without fall-off).
// The far thinning keeps the instances of rank below its fraction `kept` the same way (all
// of them at a fraction of 1).
fn growth(lod: Lod, eye: vec2<f32>, root: vec3<f32>, appear: f32, kept: f32) -> f32 {
    let distance = length(root.xz - eye);
    let span = max(lod.falloff_far - lod.falloff_near, 1e-3);
    let near = clamp(1.0 - (distance - lod.falloff_near) / span, 0.0, 1.0);
    let factor = max(lod.falloff_floor, near);
    let grown = clamp((factor - appear) / lod.fade_band, 0.0, 1.0);
    let thinned = clamp((kept * (1.0 + lod.fade_band) - appear) / lod.fade_band, 0.0, 1.0);
    return select(grown, 1.0, lod.falloff_on == 0u) * thinned;
}
