// Instanced foliage: one chunk's instances of one mesh, swayed by a world-space wind field
// and grown in or out by level of detail; with `RWT_SURFACE`, a primitive of a game's asset
// lit as Bevy lights its glTF material (normal map, metallic-roughness, emissive, occlusion). The main pass lights it with Bevy's PBR lighting
// (scene lights, ambient light, received shadows, distance fog); the prepass pipeline
// (`PREPASS_PIPELINE`) writes its depth, normals and motion vectors (the previous frame's
// sway included) and its depth into shadow maps.

#ifdef PREPASS_PIPELINE
#import bevy_pbr::mesh_view_bindings::view
#import bevy_pbr::prepass_bindings::previous_view_uniforms
#import bevy_render::globals::Globals
// The prepass view layout has the globals at binding 1.
@group(0) @binding(1) var<uniform> globals: Globals;
#else
#import bevy_pbr::mesh_view_bindings::{view, globals}
#import bevy_pbr::{pbr_types, pbr_functions}
#import bevy_pbr::mesh_types::MESH_FLAGS_SHADOW_RECEIVER_BIT
#endif
#import bevy_pbr::view_transformations::position_world_to_clip
#import rwt::fade::{Lod, kept_fraction, growth}

struct Chunk {
    // The chunk's corner, and the mesh's top (its height at scale 1).
    origin: vec3<f32>,
    mesh_top: f32,
    base_color: vec4<f32>,
    tip_color: vec4<f32>,
    color_variation: f32,
    roughness: f32,
    wind_response: f32,
    // Height fraction where the tip colour starts.
    tip_from: f32,
    // The level of detail: fall-off, growth and far thinning.
    lod: Lod,
    // The wind: its direction (x, z), strength, frequency and speed.
    wind_direction: vec2<f32>,
    wind_strength: f32,
    wind_frequency: f32,
    wind_speed: f32,
    bend_response: f32,
    alpha_cutoff: f32,
    // 1 when the class has a texture.
    textured: u32,
    // The crossfade band (distance from the eye to a root) impostors fade in over, and the
    // one a class's mesh fades out over where impostors take over.
    fade_in_from: f32,
    fade_in_to: f32,
    fade_out_from: f32,
    fade_out_to: f32,
    // Half the width and height one baked view covers, at scale 1.
    impostor_half: vec2<f32>,
    // Where the views look (the mesh's bounds' centre), and how many there are around.
    impostor_center: vec3<f32>,
    impostor_views: u32,
    // Elevations baked.
    impostor_rows: u32,
    // An asset's surface: its metallic and reflectance factors, and the light it emits.
    metallic: f32,
    reflectance: f32,
    emissive: vec4<f32>,
};

@group(2) @binding(0) var<uniform> chunk: Chunk;

struct Frame {
    // Where the main camera is: shadow passes grow instances as that camera sees them, not
    // as the light does.
    viewer: vec3<f32>,
    // 1 when any blade leans in the bend field.
    bends: u32,
    // The bend field's min corner (x, z), and 1 / its side.
    bend_min: vec2<f32>,
    bend_scale: f32,
};

@group(2) @binding(1) var<uniform> frame: Frame;
// How far blades lean (x, z) around the main camera, where benders passed.
@group(2) @binding(2) var bend_field: texture_2d<f32>;
@group(2) @binding(3) var bend_sampler: sampler;
#ifdef RWT_TEXTURE
// The class's base-colour texture; alpha below the cut-off is cut out in every pass.
@group(2) @binding(4) var base_texture: texture_2d<f32>;
@group(2) @binding(5) var base_sampler: sampler;
#endif
#ifdef RWT_SURFACE
#ifdef RWT_TEXTURE
// An asset's maps (white where it has none): normals, metallic-roughness, emission,
// occlusion.
@group(2) @binding(6) var normal_texture: texture_2d<f32>;
@group(2) @binding(7) var normal_sampler: sampler;
@group(2) @binding(8) var metallic_roughness_texture: texture_2d<f32>;
@group(2) @binding(9) var metallic_roughness_sampler: sampler;
@group(2) @binding(10) var emissive_texture: texture_2d<f32>;
@group(2) @binding(11) var emissive_sampler: sampler;
@group(2) @binding(12) var occlusion_texture: texture_2d<f32>;
@group(2) @binding(13) var occlusion_sampler: sampler;
#endif
#endif

struct Vertex {
    @location(0) position: vec3<f32>,
#ifdef RWT_NORMALS
    @location(1) normal: vec3<f32>,
#endif
#ifdef RWT_TEXTURE
    @location(2) uv: vec2<f32>,
#endif
#ifdef RWT_NORMAL_MAP
    @location(3) tangent: vec4<f32>,
#endif
#ifdef RWT_VERTEX_COLORS
    @location(4) vertex_color: vec4<f32>,
#endif
    // Offset from the chunk corner (xyz), scale (w).
    @location(8) offset_scale: vec4<f32>,
    // Yaw (turns), appearance factor, tint, tilt (the up axis's x and z as two signed
    // bytes of a 16-bit unorm: low byte x, high byte z, in 127ths).
    @location(9) yaw_appear_tint: vec4<f32>,
};

struct VertexOutput {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec4<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) color: vec4<f32>,
#ifdef MOTION_VECTOR_PREPASS
    @location(3) previous_world_position: vec4<f32>,
#endif
#ifdef UNCLIPPED_DEPTH_ORTHO_EMULATION
    @location(4) unclipped_depth: f32,
#endif
#ifdef RWT_TEXTURE
    @location(5) uv: vec2<f32>,
#endif
#ifdef RWT_IMPOSTOR
    // The instance's turn (cosine, sine) and its crossfade's dither level (-16..0).
    @location(6) @interpolate(flat) impostor: vec4<f32>,
#endif
#ifdef RWT_FADE_OUT
    // The mesh's dither level as impostors take over (0..16).
    @location(7) @interpolate(flat) fade_out: f32,
#endif
#ifdef RWT_NORMAL_MAP
    @location(8) world_tangent: vec4<f32>,
#endif
#ifdef RWT_FADE_IN
    // The mesh's dither level as it takes over from a nearer level of detail (-16..0).
    @location(9) @interpolate(flat) fade_in: f32,
#endif
};

fn hash2(p: vec2<f32>) -> f32 {
    let q = fract(p * vec2<f32>(0.1031, 0.1030));
    let r = q + dot(q, q.yx + 33.33);
    return fract((r.x + r.y) * r.x);
}

// Smooth value noise in [0, 1]: the gust field.
fn value_noise(p: vec2<f32>) -> f32 {
    let i = floor(p);
    let f = fract(p);
    let u = f * f * (3.0 - 2.0 * f);
    let a = hash2(i);
    let b = hash2(i + vec2<f32>(1.0, 0.0));
    let c = hash2(i + vec2<f32>(0.0, 1.0));
    let d = hash2(i + vec2<f32>(1.0, 1.0));
    return mix(mix(a, b, u.x), mix(c, d, u.x), u.y);
}

// No branch below depends on uniforms alone (`select` and factors instead): Mesa's lavapipe
// inlines the uniforms that steer branches and compiles the shader anew at every draw whose
// values it has not seen, which with one draw per chunk and view is a compile per draw,
// and memory that grows by megabytes a second.

// Where the level of detail is measured from: the view's camera, or the main camera in
// shadow passes.
fn eye_xz() -> vec2<f32> {
#ifdef RWT_SHADOW_PASS
    return frame.viewer.xz;
#else
    return view.world_position.xz;
#endif
}

// Sideways displacement of a point at height fraction `t` (0 root, 1 tip) of an instance
// rooted at `root`: gusts travelling with the wind plus a small per-instance flutter.
fn sway(root: vec3<f32>, t: f32, tint: f32, height: f32, time: f32) -> vec3<f32> {
    let dir = normalize(chunk.wind_direction + vec2<f32>(1e-5, 0.0));
    let drift = dir * chunk.wind_speed * time;
    let gust = value_noise((root.xz - drift) * chunk.wind_frequency);
    let flutter = 0.15 * sin(time * 2.3 + tint * 6.2831) * (0.5 + gust);
    let amount = chunk.wind_strength * chunk.wind_response * (0.25 + gust + flutter) * height;
    let bend = t * t * amount;
    return vec3<f32>(dir.x * bend, -0.3 * abs(bend) * t, dir.y * bend);
}

// The lean of an instance rooted at `root` (x, z; length 0..1, 1 is flat): none outside
// the field or while nothing leans; a class that does not respond (no `RWT_BEND`) never
// reads the field.
fn lean_at(root: vec3<f32>) -> vec2<f32> {
#ifdef RWT_BEND
    let uv = (root.xz - frame.bend_min) * frame.bend_scale;
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) {
        return vec2<f32>(0.0);
    }
    let response = chunk.bend_response * f32(frame.bends);
    let lean = textureSampleLevel(bend_field, bend_sampler, uv, 0.0).xy * response;
    let amount = length(lean);
    return select(lean, lean / amount, amount > 1.0);
#else
    return vec2<f32>(0.0);
#endif
}

// Turns `v` (relative to the root) about the horizontal axis across `dir` by the angle
// whose sine and cosine are `s`, `c`: the blade falls towards `dir`.
fn fall(v: vec3<f32>, dir: vec2<f32>, s: f32, c: f32) -> vec3<f32> {
    let along = dot(v.xz, dir);
    let turned = along * c + v.y * s;
    let up = v.y * c - along * s;
    return vec3<f32>(v.x + dir.x * (turned - along), up, v.z + dir.y * (turned - along));
}

// An instance's vertex: where it is at `time`, its normal and its height fraction; the
// wind's part of `world` and what it was computed from, for the previous frame's position.
struct Placed {
    world: vec3<f32>,
    normal: vec3<f32>,
    t: f32,
    wind: vec3<f32>,
    root: vec3<f32>,
    tint: f32,
    height: f32,
    calm: f32,
#ifdef RWT_NORMAL_MAP
    tangent: vec4<f32>,
#endif
};

// The instance's up axis from its packed tilt (0: straight up).
fn instance_up(packed: f32) -> vec3<f32> {
    let bits = u32(round(packed * 65535.0));
    let lo = f32(bits & 255u);
    let hi = f32(bits >> 8u);
    // Two's complement bytes, without a branch: 256 less from 128 on.
    let x = (lo - 256.0 * step(128.0, lo)) / 127.0;
    let z = (hi - 256.0 * step(128.0, hi)) / 127.0;
    return normalize(vec3<f32>(x, sqrt(max(1.0 - x * x - z * z, 0.0)), z));
}

// `v` turned by the rotation that takes y onto `up` (Rodrigues, with w = y x up).
fn tilt(v: vec3<f32>, up: vec3<f32>) -> vec3<f32> {
    let w = vec3<f32>(up.z, 0.0, -up.x);
    let wv = cross(w, v);
    return v + wv + cross(w, wv) / (1.0 + up.y);
}

// Where distances are measured from, as Bevy's visibility ranges measure them: the view's
// camera, or the main camera in shadow passes.
fn lod_eye() -> vec3<f32> {
#ifdef RWT_SHADOW_PASS
    return frame.viewer;
#else
    return view.world_position;
#endif
}

// Bevy's ordered dither (`visibility_range_dither`): discards the fragment at `frag_coord`
// of a look at dither `level`: 0 whole, -16..0 fading in, 0..16 fading out, +-16 gone.
fn dither(frag_coord: vec4<f32>, level: f32) {
    let coords = vec2<u32>(floor(frag_coord.xy)) % 4u;
    let map = vec4<u32>(0x0a020800u, 0x060e040cu, 0x09010b03u, 0x050d070fu);
    let threshold = f32((map[coords.y] >> (coords.x * 8u)) & 0xffu);
    let gone = abs(level) >= 16.0;
    let leaving = level > 0.0 && level + threshold >= 16.0;
    let coming = level < 0.0 && 1.0 + level + threshold <= 0.0;
    if gone || leaving || coming {
        discard;
    }
}

// The crossfades between a class's levels of detail and its impostors this fragment takes
// part in: an impostor or a mesh fading in, a mesh fading out.
fn crossfade(in: VertexOutput) {
#ifdef RWT_IMPOSTOR
    dither(in.clip_position, in.impostor.z);
#endif
#ifdef RWT_FADE_IN
    dither(in.clip_position, in.fade_in);
#endif
#ifdef RWT_FADE_OUT
    dither(in.clip_position, in.fade_out);
#endif
}

// The dither level of a look (an impostor, a farther level of detail) `d` from the eye as
// it takes over: -16 (not drawn) before its crossfade band, rising to 0 (whole) at its
// end. The look it takes over from fades out over the same band with the level 16 more
// (Bevy's visibility range, or `fade_out_level`), so every pixel shows one of the two.
fn fade_in_level(d: f32) -> f32 {
    let span = max(chunk.fade_in_to - chunk.fade_in_from, 1e-3);
    return -16.0 + clamp(round((d - chunk.fade_in_from) / span * 16.0), 0.0, 16.0);
}

// Whether the mesh of an instance at `root` is drawn at all: not once a farther look took
// over, nor before its own crossfade in begins.
fn mesh_shown(root: vec3<f32>) -> bool {
    var shown = fade_out_level(root) < 16.0;
#ifdef RWT_FADE_IN
    shown = shown && fade_in_level(distance(lod_eye(), root)) > -16.0;
#endif
    return shown;
}

// The dither level of a class's mesh at `root` as its impostors take over: 0 (whole)
// before their crossfade band, rising to 16 (gone) at its end; 0 without impostors.
fn fade_out_level(root: vec3<f32>) -> f32 {
#ifdef RWT_FADE_OUT
    let span = max(chunk.fade_out_to - chunk.fade_out_from, 1e-3);
    let d = distance(lod_eye(), root);
    return clamp(round((d - chunk.fade_out_from) / span * 16.0), 0.0, 16.0);
#else
    return 0.0;
#endif
}

fn place(in: Vertex, time: f32) -> Placed {
    let root = chunk.origin + in.offset_scale.xyz;
    let yaw = in.yaw_appear_tint.x * 6.2831853;
    let tint = in.yaw_appear_tint.z;
    let eye = eye_xz();
    let kept = kept_fraction(chunk.lod, eye, root);
    // A mesh another look replaced collapses to its root.
    let shown = select(0.0, 1.0, mesh_shown(root));
    let scale = in.offset_scale.w * growth(chunk.lod, eye, root, in.yaw_appear_tint.y, kept) * shown;
    let c = cos(yaw);
    let s = sin(yaw);
    let up = instance_up(in.yaw_appear_tint.w);
    // A thinned field's instances are widened to cover as the whole field did (seen from
    // the side, an instance's cover grows with its width).
    let widen = 1.0 / kept;
    let local = in.position * scale * vec3<f32>(widen, 1.0, widen);
    var turned = vec3<f32>(c * local.x + s * local.z, local.y, -s * local.x + c * local.z);
#ifdef RWT_NORMALS
    let n = in.normal;
    var normal = vec3<f32>(c * n.x + s * n.z, n.y, -s * n.x + c * n.z);
#else
    var normal = vec3<f32>(0.0, 1.0, 0.0);
#endif
#ifdef RWT_NORMAL_MAP
    let m = in.tangent.xyz;
    var tangent = vec3<f32>(c * m.x + s * m.z, m.y, -s * m.x + c * m.z);
    tangent = tilt(tangent, up);
#endif
    // Standing along the surface (a class's stance); upright instances turn by nothing.
    turned = tilt(turned, up);
    normal = tilt(normal, up);
    // Where a bender passed, the blade falls away from it, up to 80 degrees.
    let lean = lean_at(root);
    let amount = length(lean);
    if amount > 1e-3 {
        let dir = lean / amount;
        let angle = amount * 1.4;
        turned = fall(turned, dir, sin(angle), cos(angle));
        normal = fall(normal, dir, sin(angle), cos(angle));
#ifdef RWT_NORMAL_MAP
        tangent = fall(tangent, dir, sin(angle), cos(angle));
#endif
    }
    var out: Placed;
    out.t = clamp(in.position.y / chunk.mesh_top, 0.0, 1.0);
    out.root = root;
    out.tint = tint;
    out.height = chunk.mesh_top * scale;
    out.calm = 1.0 - amount;
    out.wind = sway(root, out.t, tint, out.height, time) * out.calm;
    out.world = root + turned + out.wind;
#ifdef RWT_SURFACE
    out.normal = normalize(normal);
#else
    // Blades read as blades when their normals lean towards the sky.
    out.normal = normalize(mix(normal, vec3<f32>(0.0, 1.0, 0.0), 0.45));
#endif
#ifdef RWT_NORMAL_MAP
    out.tangent = vec4<f32>(normalize(tangent), in.tangent.w);
#endif
    return out;
}

// Where `placed` was at `time`: only the wind moves an instance from frame to frame (the
// bend field is this frame's in both), so the rest of `place` is not computed twice.
fn placed_at(placed: Placed, time: f32) -> vec3<f32> {
    let wind = sway(placed.root, placed.t, placed.tint, placed.height, time) * placed.calm;
    return placed.world - placed.wind + wind;
}

#ifdef RWT_IMPOSTOR
// An impostor's card: centred on the baked views' centre (turned with the instance), facing
// the eye, pulled towards it by half its width (so that the ground around the root does
// not cut it) and shrunk to keep its size on screen. It shows the view nearest to the
// direction of the eye in the instance's frame. A card not drawn collapses to its root.
fn card(in: Vertex) -> VertexOutput {
    let root = chunk.origin + in.offset_scale.xyz;
    let yaw = in.yaw_appear_tint.x * 6.2831853;
    let c = cos(yaw);
    let s = sin(yaw);
    let xz = eye_xz();
    let kept = kept_fraction(chunk.lod, xz, root);
    let scale = in.offset_scale.w * growth(chunk.lod, xz, root, in.yaw_appear_tint.y, kept);
    let eye = lod_eye();
    let level = fade_in_level(distance(eye, root));
    let m = chunk.impostor_center * scale;
    let center = root + vec3<f32>(c * m.x + s * m.z, m.y, -s * m.x + c * m.z);
    let dist = max(distance(eye, center), 1e-3);
    let dir = (eye - center) / dist;
    let local = vec3<f32>(c * dir.x - s * dir.z, dir.y, s * dir.x + c * dir.z);
    let views = f32(chunk.impostor_views);
    let rows = f32(chunk.impostor_rows);
    let turn = atan2(local.x, local.z) / 6.2831853 * views;
    let i = (round(turn) % views + views) % views;
    let j = clamp(round(asin(clamp(local.y, 0.0, 1.0)) / 1.5707963 * rows), 0.0, rows - 1.0);
    var right = cross(vec3<f32>(0.0, 1.0, 0.0), dir);
    right = select(vec3<f32>(1.0, 0.0, 0.0), normalize(right), dot(right, right) > 1e-8);
    let up = cross(dir, right);
    let pull = min(chunk.impostor_half.x * scale, 0.5 * dist);
    let size = scale * (dist - pull) / dist * select(0.0, 1.0, level > -16.0 && scale > 0.0);
    let across = in.position.x * size;
    let high = (in.position.y - chunk.impostor_center.y) * size;
    let world = center + dir * pull + right * across + up * high;
    var out: VertexOutput;
    out.world_position = vec4<f32>(world, 1.0);
    out.clip_position = position_world_to_clip(world);
    out.world_normal = dir;
    // The class's colour variation per instance, as its meshes have it.
    let variation = (in.yaw_appear_tint.z - 0.5) * chunk.color_variation;
    out.color = vec4<f32>(vec3<f32>(1.0 + variation) + vec3<f32>(variation * 0.15, variation * 0.05, 0.0), 1.0);
#ifdef MOTION_VECTOR_PREPASS
    out.previous_world_position = out.world_position;
#endif
    out.uv = vec2<f32>((i + in.uv.x) / (2.0 * views), (j + in.uv.y) / rows);
    out.impostor = vec4<f32>(c, s, level, 0.0);
#ifdef UNCLIPPED_DEPTH_ORTHO_EMULATION
    out.unclipped_depth = out.clip_position.z;
    out.clip_position.z = min(out.clip_position.z, 1.0);
#endif
    return out;
}

// The atlas's normal where the albedo is read at `uv`, in the world (the instance turned).
fn impostor_normal(uv: vec2<f32>, turn: vec4<f32>) -> vec3<f32> {
    let n = textureSample(base_texture, base_sampler, uv + vec2<f32>(0.5, 0.0)).xyz * 2.0 - 1.0;
    return normalize(vec3<f32>(turn.x * n.x + turn.y * n.z, n.y, -turn.y * n.x + turn.x * n.z));
}
#endif

@vertex
fn vertex(in: Vertex) -> VertexOutput {
#ifdef RWT_IMPOSTOR
    return card(in);
#else
    let placed = place(in, globals.time);
    let tint = in.yaw_appear_tint.z;
    let variation = (tint - 0.5) * chunk.color_variation;
    let tip_start = chunk.tip_from;
    var shade = mix(chunk.base_color, chunk.tip_color, clamp((placed.t - tip_start) / (1.0 - tip_start), 0.0, 1.0));
#ifdef RWT_VERTEX_COLORS
    shade = shade * in.vertex_color;
#endif
    var out: VertexOutput;
    out.world_position = vec4<f32>(placed.world, 1.0);
    out.clip_position = position_world_to_clip(placed.world);
    out.world_normal = placed.normal;
    // The alpha is the cut-out's factor: 1 but for an asset's surface.
#ifdef RWT_SURFACE
    let alpha = shade.a;
#else
    let alpha = 1.0;
#endif
    out.color = vec4<f32>(shade.rgb * (1.0 + variation) + vec3<f32>(variation * 0.15, variation * 0.05, 0.0), alpha);
#ifdef MOTION_VECTOR_PREPASS
    out.previous_world_position = vec4<f32>(placed_at(placed, globals.time - globals.delta_time), 1.0);
#endif
#ifdef RWT_NORMAL_MAP
    out.world_tangent = placed.tangent;
#endif
#ifdef RWT_TEXTURE
    out.uv = in.uv;
#endif
#ifdef RWT_FADE_OUT
    out.fade_out = fade_out_level(chunk.origin + in.offset_scale.xyz);
#endif
#ifdef RWT_FADE_IN
    out.fade_in = fade_in_level(distance(lod_eye(), chunk.origin + in.offset_scale.xyz));
#endif
#ifdef UNCLIPPED_DEPTH_ORTHO_EMULATION
    out.unclipped_depth = out.clip_position.z;
    out.clip_position.z = min(out.clip_position.z, 1.0);
#endif
    return out;
#endif
}

#ifdef RWT_TEXTURE
// The texture at the fragment, which is cut out where its alpha times `alpha` (the vertex
// colour's) is below the cut-off.
fn cut_out(uv: vec2<f32>, alpha: f32) -> vec4<f32> {
    let texel = textureSample(base_texture, base_sampler, uv);
    if texel.a * alpha < chunk.alpha_cutoff {
        discard;
    }
    return texel;
}
#endif

#ifdef PREPASS_PIPELINE
#ifdef PREPASS_FRAGMENT
struct FragmentOutput {
#ifdef NORMAL_PREPASS
    @location(0) normal: vec4<f32>,
#endif
#ifdef MOTION_VECTOR_PREPASS
    @location(1) motion_vector: vec2<f32>,
#endif
#ifdef UNCLIPPED_DEPTH_ORTHO_EMULATION
    @builtin(frag_depth) frag_depth: f32,
#endif
};

@fragment
fn fragment(in: VertexOutput, @builtin(front_facing) is_front: bool) -> FragmentOutput {
#ifdef RWT_IMPOSTOR
    let n = impostor_normal(in.uv, in.impostor);
#else
    let n = facing_normal(in.world_normal, is_front);
#endif
#ifdef RWT_TEXTURE
    _ = cut_out(in.uv, in.color.a);
#endif
    crossfade(in);
    var out: FragmentOutput;
#ifdef NORMAL_PREPASS
    out.normal = vec4<f32>(n * 0.5 + vec3<f32>(0.5), 1.0);
#endif
#ifdef MOTION_VECTOR_PREPASS
    let now_t = view.unjittered_clip_from_world * in.world_position;
    let then_t = previous_view_uniforms.clip_from_world * in.previous_world_position;
    out.motion_vector = (now_t.xy / now_t.w - then_t.xy / then_t.w) * vec2<f32>(0.5, -0.5);
#endif
#ifdef UNCLIPPED_DEPTH_ORTHO_EMULATION
    out.frag_depth = in.unclipped_depth;
#endif
    return out;
}
#else
#ifdef RWT_TEXTURE
// Depth alone (a shadow map, a depth prepass): only the cut-out and the crossfades.
@fragment
fn fragment(in: VertexOutput) {
    _ = cut_out(in.uv, in.color.a);
    crossfade(in);
}
#else
#ifdef RWT_FADE_OUT
// Depth alone of an untextured class: only the crossfades with its other looks.
@fragment
fn fragment(in: VertexOutput) {
    crossfade(in);
}
#else
#ifdef RWT_FADE_IN
@fragment
fn fragment(in: VertexOutput) {
    crossfade(in);
}
#endif
#endif
#endif
#endif
#else
@fragment
fn fragment(in: VertexOutput, @builtin(front_facing) is_front: bool) -> @location(0) vec4<f32> {
#ifdef RWT_IMPOSTOR
    let n = impostor_normal(in.uv, in.impostor);
#else
#ifdef RWT_NORMAL_MAP
    let n = mapped_normal(in, is_front);
#else
    let n = facing_normal(in.world_normal, is_front);
#endif
#endif
    var color = in.color;
#ifdef RWT_TEXTURE
    color = vec4<f32>(color.rgb * cut_out(in.uv, in.color.a).rgb, 1.0);
#endif
    crossfade(in);
    var pbr_input = pbr_types::pbr_input_new();
    pbr_input.material.base_color = vec4<f32>(color.rgb, 1.0);
    pbr_input.material.perceptual_roughness = chunk.roughness;
    pbr_input.material.reflectance = vec3<f32>(0.2);
    pbr_input.material.flags = pbr_types::STANDARD_MATERIAL_FLAGS_FOG_ENABLED_BIT;
#ifdef RWT_SURFACE
    surface_maps(&pbr_input, in);
#endif
    pbr_input.frag_coord = in.clip_position;
    pbr_input.world_position = in.world_position;
    pbr_input.world_normal = n;
    pbr_input.N = n;
    pbr_input.V = pbr_functions::calculate_view(in.world_position, false);
    pbr_input.flags = MESH_FLAGS_SHADOW_RECEIVER_BIT;
    let lit = pbr_functions::apply_pbr_lighting(pbr_input);
    return pbr_functions::main_pass_post_lighting_processing(pbr_input, lit);
}
#endif

// The normal of the side seen: blades are seen from both sides, their normals leaning
// towards the sky; a single-sided surface's back is never drawn, a double-sided one's
// turns its normal round.
fn facing_normal(world_normal: vec3<f32>, is_front: bool) -> vec3<f32> {
    let n = normalize(world_normal);
#ifdef RWT_SURFACE
    return select(-n, n, is_front);
#else
    if is_front {
        return n;
    }
    return vec3<f32>(-n.x, n.y, -n.z);
#endif
}

#ifndef PREPASS_PIPELINE
#ifdef RWT_SURFACE
// An asset's maps at the fragment, into its lighting's input: roughness, metallic,
// emission and occlusion, and the normal map's normal.
fn surface_maps(pbr_input: ptr<function, pbr_types::PbrInput>, in: VertexOutput) {
#ifdef RWT_TEXTURE
    let mr = textureSample(metallic_roughness_texture, metallic_roughness_sampler, in.uv);
    let emitted = textureSample(emissive_texture, emissive_sampler, in.uv).rgb;
    let occlusion = textureSample(occlusion_texture, occlusion_sampler, in.uv).r;
#else
    let mr = vec4<f32>(1.0);
    let emitted = vec3<f32>(1.0);
    let occlusion = 1.0;
#endif
    (*pbr_input).material.perceptual_roughness = chunk.roughness * mr.g;
    (*pbr_input).material.metallic = chunk.metallic * mr.b;
    (*pbr_input).material.reflectance = vec3<f32>(chunk.reflectance);
    (*pbr_input).material.emissive = vec4<f32>(chunk.emissive.rgb * emitted, 1.0);
    (*pbr_input).diffuse_occlusion = vec3<f32>(occlusion);
}

#ifdef RWT_NORMAL_MAP
// The normal map's normal, in the world (mikktspace, as Bevy's `StandardMaterial` reads it).
fn mapped_normal(in: VertexOutput, is_front: bool) -> vec3<f32> {
    // The back of a double-sided surface turns the map's normal round.
#ifdef RWT_DOUBLE_SIDED
    let double_sided = true;
#else
    let double_sided = false;
#endif
    let tbn = pbr_functions::calculate_tbn_mikktspace(in.world_normal, in.world_tangent);
    let nt = textureSample(normal_texture, normal_sampler, in.uv).rgb;
    return pbr_functions::apply_normal_mapping(0u, tbn, double_sided, is_front, nt);
}
#endif
#endif
#endif
