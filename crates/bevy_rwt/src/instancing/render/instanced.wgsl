// Instanced foliage: one chunk's instances of one mesh, lit by Bevy's PBR lighting (scene
// lights, ambient light, received shadows, distance fog), swayed by a world-space wind
// field and grown in or out by level of detail.

#import bevy_pbr::mesh_view_bindings::{view, globals}
#import bevy_pbr::view_transformations::position_world_to_clip
#import bevy_pbr::{pbr_types, pbr_functions}
#import bevy_pbr::mesh_types::MESH_FLAGS_SHADOW_RECEIVER_BIT

struct Chunk {
    // Chunk corner (xyz), mesh top (w).
    origin: vec4<f32>,
    base_color: vec4<f32>,
    tip_color: vec4<f32>,
    // Colour variation, roughness, wind response, fade band.
    params: vec4<f32>,
    // Fall-off near, far, enabled, floor.
    falloff: vec4<f32>,
    // Wind direction (x, z), strength, frequency.
    wind: vec4<f32>,
    // Wind speed.
    wind_motion: vec4<f32>,
    // Height fraction where the tip colour starts, unused.
    shading: vec4<f32>,
};

@group(2) @binding(0) var<uniform> chunk: Chunk;

struct Vertex {
    @location(0) position: vec3<f32>,
#ifdef RWT_NORMALS
    @location(1) normal: vec3<f32>,
#endif
    // Offset from the chunk corner (xyz), scale (w).
    @location(8) offset_scale: vec4<f32>,
    // Yaw (turns), appearance factor, tint, unused.
    @location(9) yaw_appear_tint: vec4<f32>,
};

struct VertexOutput {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec4<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) color: vec4<f32>,
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

// Growth of an instance: 0 until the level-of-detail factor at its place reaches the one at
// which its point appears, then up to 1 over the fade band.
fn growth(root: vec3<f32>, appear: f32) -> f32 {
    if chunk.falloff.z == 0.0 {
        return 1.0;
    }
    let distance = length(root.xz - view.world_position.xz);
    let span = max(chunk.falloff.y - chunk.falloff.x, 1e-3);
    let factor = max(chunk.falloff.w, clamp(1.0 - (distance - chunk.falloff.x) / span, 0.0, 1.0));
    return clamp((factor - appear) / chunk.params.w, 0.0, 1.0);
}

// Sideways displacement of a point at height fraction `t` (0 root, 1 tip) of an instance
// rooted at `root`: gusts travelling with the wind plus a small per-instance flutter.
fn sway(root: vec3<f32>, t: f32, tint: f32, height: f32) -> vec3<f32> {
    let dir = normalize(chunk.wind.xy + vec2<f32>(1e-5, 0.0));
    let time = globals.time;
    let drift = dir * chunk.wind_motion.x * time;
    let gust = value_noise((root.xz - drift) * chunk.wind.w);
    let flutter = 0.15 * sin(time * 2.3 + tint * 6.2831) * (0.5 + gust);
    let amount = chunk.wind.z * chunk.params.z * (0.25 + gust + flutter) * height;
    let bend = t * t * amount;
    return vec3<f32>(dir.x * bend, -0.3 * abs(bend) * t, dir.y * bend);
}

@vertex
fn vertex(in: Vertex) -> VertexOutput {
    let root = chunk.origin.xyz + in.offset_scale.xyz;
    let yaw = in.yaw_appear_tint.x * 6.2831853;
    let tint = in.yaw_appear_tint.z;
    let scale = in.offset_scale.w * growth(root, in.yaw_appear_tint.y);
    let c = cos(yaw);
    let s = sin(yaw);
    let local = in.position * scale;
    let turned = vec3<f32>(c * local.x + s * local.z, local.y, -s * local.x + c * local.z);
    let t = clamp(in.position.y / chunk.origin.w, 0.0, 1.0);
    let world = root + turned + sway(root, t, tint, chunk.origin.w * scale);

#ifdef RWT_NORMALS
    let n = in.normal;
    let normal = vec3<f32>(c * n.x + s * n.z, n.y, -s * n.x + c * n.z);
#else
    let normal = vec3<f32>(0.0, 1.0, 0.0);
#endif

    let variation = (tint - 0.5) * chunk.params.x;
    let tip_start = chunk.shading.x;
    let shade = mix(chunk.base_color, chunk.tip_color, clamp((t - tip_start) / (1.0 - tip_start), 0.0, 1.0));
    var out: VertexOutput;
    out.world_position = vec4<f32>(world, 1.0);
    out.clip_position = position_world_to_clip(world);
    // Blades read as blades when their normals lean towards the sky.
    out.world_normal = normalize(mix(normal, vec3<f32>(0.0, 1.0, 0.0), 0.45));
    out.color = vec4<f32>(shade.rgb * (1.0 + variation) + vec3<f32>(variation * 0.15, variation * 0.05, 0.0), 1.0);
    return out;
}

@fragment
fn fragment(in: VertexOutput, @builtin(front_facing) is_front: bool) -> @location(0) vec4<f32> {
    var n = normalize(in.world_normal);
    if !is_front {
        n = vec3<f32>(-n.x, n.y, -n.z);
    }
    var pbr_input = pbr_types::pbr_input_new();
    pbr_input.material.base_color = in.color;
    pbr_input.material.perceptual_roughness = chunk.params.y;
    pbr_input.material.reflectance = vec3<f32>(0.2);
    pbr_input.material.flags = pbr_types::STANDARD_MATERIAL_FLAGS_FOG_ENABLED_BIT;
    pbr_input.frag_coord = in.clip_position;
    pbr_input.world_position = in.world_position;
    pbr_input.world_normal = n;
    pbr_input.N = n;
    pbr_input.V = pbr_functions::calculate_view(in.world_position, false);
    pbr_input.flags = MESH_FLAGS_SHADOW_RECEIVER_BIT;
    var color = pbr_functions::apply_pbr_lighting(pbr_input);
    color = pbr_functions::main_pass_post_lighting_processing(pbr_input, color);
    return color;
}
