// The level of detail that both the instanced shader and culling per instance apply: far
// thinning and growth by rank. Their uniforms differ, so the settings come as a `Fade`.

#define_import_path rwt::fade

struct Fade {
    // Where distances are measured from (x, z).
    eye: vec2<f32>,
    // The fall-off: near, far, the factor's floor, whether there is one.
    falloff_near: f32,
    falloff_far: f32,
    falloff_floor: f32,
    falloff_on: bool,
    // The band of ranks an instance grows over.
    fade_band: f32,
    // Far thinning: its distance, its floor, whether it is on.
    thinning_from: f32,
    thinning_floor: f32,
    thinning_on: bool,
};

// Far thinning at `root`: the fraction of instances kept there (1 without thinning).
fn kept_fraction(fade: Fade, root: vec3<f32>) -> f32 {
    let ratio = fade.thinning_from / max(length(root.xz - fade.eye), 1e-3);
    let kept = clamp(ratio * ratio, fade.thinning_floor, 1.0);
    return select(1.0, kept, fade.thinning_on);
}

// Growth of an instance: 0 until the level-of-detail factor at its place reaches the one at
// which its point appears, then up to 1 over the fade band (always 1 without fall-off).
// The far thinning keeps the instances of rank below its fraction `kept` the same way (all
// of them at a fraction of 1).
fn growth(fade: Fade, root: vec3<f32>, appear: f32, kept: f32) -> f32 {
    let distance = length(root.xz - fade.eye);
    let span = max(fade.falloff_far - fade.falloff_near, 1e-3);
    let near = clamp(1.0 - (distance - fade.falloff_near) / span, 0.0, 1.0);
    let factor = max(fade.falloff_floor, near);
    let grown = clamp((factor - appear) / fade.fade_band, 0.0, 1.0);
    let thinned = clamp((kept * (1.0 + fade.fade_band) - appear) / fade.fade_band, 0.0, 1.0);
    return select(grown, 1.0, !fade.falloff_on) * thinned;
}
