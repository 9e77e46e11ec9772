//! The instanced shader against naga, without a GPU: composed with Bevy's own shader
//! library (its WGSL sources, found through `cargo metadata`) for every permutation of the
//! definitions the pipelines set, as Bevy's `ShaderCache` composes it (validating in test
//! builds), and its uniform structs' layouts against the Rust structs that fill them.

use super::uniforms::LodUniform;
use super::uniforms::{ChunkUniform, FrameUniform};
use bevy::asset::AssetId;
use bevy::asset::uuid::Uuid;
use bevy::math::{Vec2, Vec3, Vec4};
use bevy::render::render_resource::ShaderType;
use bevy::render::render_resource::encase::internal::WriteInto;
use bevy::render::render_resource::encase::{StorageBuffer, UniformBuffer};
use bevy::render::render_resource::{DownlevelFlags, WgpuFeatures};
use bevy::shader::{
    Shader, ShaderCache, ShaderCacheError, ShaderCacheSource, ShaderDefVal, ValidateShader,
};
use std::path::{Path, PathBuf};

/// The crates whose WGSL the instanced shader imports, directly or through others.
const LIBRARY: [&str; 5] = [
    "bevy_pbr",
    "bevy_render",
    "bevy_core_pipeline",
    "bevy_light",
    "bevy_shader",
];

/// The host's target triple, from `rustc -vV`.
fn host() -> String {
    let out = std::process::Command::new("rustc")
        .arg("-vV")
        .output()
        .expect("rustc runs");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let line = text.lines().find_map(|l| l.strip_prefix("host: "));
    line.expect("rustc names its host").to_string()
}

/// The `src` folders of the library's crates, from `cargo metadata` (for this platform
/// only: offline, the others' packages are not there).
fn library_sources() -> Vec<PathBuf> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--offline"])
        .args(["--filter-platform", &host()])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo metadata runs");
    let text = String::from_utf8_lossy(&out.stdout);
    let paths: Vec<PathBuf> = text
        .split("\"manifest_path\":\"")
        .skip(1)
        .filter_map(|s| s.split('"').next())
        .map(PathBuf::from)
        .filter(|p| {
            let dir = p.parent().and_then(Path::file_name);
            let name = dir
                .map(|d| d.to_string_lossy().into_owned())
                .unwrap_or_default();
            LIBRARY.iter().any(|c| name.starts_with(&format!("{c}-")))
        })
        .filter_map(|p| p.parent().map(|d| d.join("src")))
        .collect();
    assert_eq!(paths.len(), LIBRARY.len(), "found {paths:?}");
    paths
}

/// Every WGSL file below `dir` that names an import path.
fn modules(dir: &Path, found: &mut Vec<(String, String)>) {
    for entry in std::fs::read_dir(dir).expect("a crate's sources").flatten() {
        let path = entry.path();
        if path.is_dir() {
            modules(&path, found);
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            let source = std::fs::read_to_string(&path).expect("a WGSL file");
            if source.contains("#define_import_path") {
                found.push((path.display().to_string(), source));
            }
        }
    }
}

/// What a test reads of a composed and validated module.
pub(super) type ReadModule =
    fn(&(), ShaderCacheSource, &ValidateShader) -> Result<String, ShaderCacheError>;

/// Reads a module's types, as `Debug` prints them (for [`struct_layout`]).
const TYPES: ReadModule = |_, source, _| match source {
    ShaderCacheSource::Naga(module) => Ok(format!("{:?}", module.types)),
    _ => Ok(String::new()),
};

/// A [`cache_with_fade_reading`] of the modules' types (`TYPES`).
pub(super) fn cache_with_fade() -> ShaderCache<String, ()> {
    cache_with_fade_reading(TYPES)
}

/// A shader cache that validates what it composes (in test builds), holding the level of
/// detail our shaders share (`rwt::fade`), whose modules are what `read` reads of them.
pub(super) fn cache_with_fade_reading(read: ReadModule) -> ShaderCache<String, ()> {
    let mut cache = ShaderCache::new((), WgpuFeatures::all(), DownlevelFlags::all(), read);
    let fade = Shader::from_wgsl(include_str!("fade.wgsl"), "fade.wgsl");
    cache.set_shader(AssetId::from(Uuid::from_u128(u128::MAX - 1)), fade);
    cache
}

/// A [`cache_with_fade`] also holding Bevy's library, set up as Bevy's plugins set it up.
fn cache_with_library() -> ShaderCache<String, ()> {
    let mut cache = cache_with_fade();
    let mut found = Vec::new();
    for dir in library_sources() {
        modules(&dir, &mut found);
    }
    for (k, (path, source)) in found.into_iter().enumerate() {
        // What bevy_pbr's plugin loads mesh_view_types.wgsl with.
        let defs = if path.ends_with("mesh_view_types.wgsl") {
            vec![
                ShaderDefVal::UInt("MAX_DIRECTIONAL_LIGHTS".into(), 10),
                ShaderDefVal::UInt("MAX_CASCADES_PER_LIGHT".into(), 4),
                ShaderDefVal::UInt("MAX_RECT_LIGHTS".into(), 8),
            ]
        } else {
            Vec::new()
        };
        let shader = Shader::from_wgsl_with_defs(source, path, defs);
        cache.set_shader(AssetId::from(Uuid::from_u128(k as u128 + 1)), shader);
    }
    cache
}

/// The class features the pipelines combine: a class's own look's, then an asset
/// surface's.
const FEATURES: [&str; 10] = [
    "RWT_NORMALS",
    "RWT_BEND",
    "RWT_TEXTURE",
    "RWT_IMPOSTOR",
    "RWT_FADE_OUT",
    "RWT_SURFACE",
    "RWT_NORMAL_MAP",
    "RWT_DOUBLE_SIDED",
    "RWT_VERTEX_COLORS",
    "RWT_FADE_IN",
];

/// Whether the pipelines can combine the features of `bits` (bit `i`: `FEATURES[i]`).
fn possible(bits: usize) -> bool {
    let has = |name: &str| bits >> FEATURES.iter().position(|f| *f == name).unwrap() & 1 == 1;
    // Impostors are always textured (their atlas), and never fade out.
    let impostor = !has("RWT_IMPOSTOR") || (has("RWT_TEXTURE") && !has("RWT_FADE_OUT"));
    // An asset's surface has no impostor; its normal map needs normals and UVs; its other
    // features, and fading in (a farther level of detail), exist only with it. Its levels'
    // crossfades are composed with every extra or none (the features are independent).
    let extras = ["RWT_NORMAL_MAP", "RWT_DOUBLE_SIDED", "RWT_VERTEX_COLORS"].map(has);
    let fades = has("RWT_FADE_IN") || has("RWT_FADE_OUT");
    let surface = match has("RWT_SURFACE") {
        true => {
            !has("RWT_IMPOSTOR")
                && (!has("RWT_NORMAL_MAP") || (has("RWT_TEXTURE") && has("RWT_NORMALS")))
                && (!fades || extras.iter().all(|e| *e) || extras.iter().all(|e| !e))
        }
        false => !has("RWT_FADE_IN") && extras.iter().all(|e| !e),
    };
    impostor && surface
}

/// The definitions of the main pass and of the depth passes (prepass and shadows), for
/// every class feature and pass option the pipelines combine.
fn permutations() -> Vec<Vec<ShaderDefVal>> {
    let global = ShaderDefVal::UInt("AVAILABLE_STORAGE_BUFFER_BINDINGS".into(), 8);
    let features = FEATURES;
    let passes = [
        "NORMAL_PREPASS",
        "MOTION_VECTOR_PREPASS",
        "UNCLIPPED_DEPTH_ORTHO_EMULATION",
        "RWT_SHADOW_PASS",
    ];
    let subset = |names: &[&str], bits: usize| -> Vec<ShaderDefVal> {
        let on = names.iter().enumerate().filter(|(i, _)| bits >> i & 1 == 1);
        on.map(|(_, n)| ShaderDefVal::from(*n)).collect()
    };
    let mut all = Vec::new();
    for f in (0..1 << features.len()).filter(|f| possible(*f)) {
        let mut main = vec![
            global.clone(),
            ShaderDefVal::UInt("MATERIAL_BIND_GROUP".into(), 3),
        ];
        main.extend(subset(&features, f));
        all.push(main);
        for p in 0..1 << passes.len() {
            let mut depth = vec![global.clone(), "PREPASS_PIPELINE".into()];
            depth.extend(subset(&features, f));
            depth.extend(subset(&passes, p));
            // The depth pipeline has a fragment where a prepass target or the emulation
            // asks for one; one that writes nothing for a textured or fading class.
            if p & 0b111 != 0 {
                depth.push("PREPASS_FRAGMENT".into());
            }
            all.push(depth);
        }
    }
    all
}

/// The address space a struct is read from: a uniform's rules are stricter (a struct
/// member starts on 16 bytes), and encase checks them when it writes one.
#[derive(Clone, Copy)]
pub(super) enum Space {
    Uniform,
    Storage,
}

/// The members (name, offset) and size of `value` as encase writes it into a buffer of
/// `space`: each member's first word holds its own marker (`markers`, in member order).
pub(super) fn encase_layout<T: ShaderType + WriteInto>(
    value: &T,
    space: Space,
    markers: &[(&str, u32)],
) -> (Vec<(String, usize)>, usize) {
    let bytes = match space {
        Space::Uniform => {
            let mut bytes = UniformBuffer::new(Vec::<u8>::new());
            bytes.write(value).expect("encase writes it");
            bytes.into_inner()
        }
        Space::Storage => {
            let mut bytes = StorageBuffer::new(Vec::<u8>::new());
            bytes.write(value).expect("encase writes it");
            bytes.into_inner()
        }
    };
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
    let members = markers.iter().map(|&(name, marker)| {
        let word = words.iter().position(|w| *w == marker);
        (
            name.to_string(),
            4 * word.unwrap_or_else(|| panic!("no marker for {name}")),
        )
    });
    (members.collect(), T::min_size().get() as usize)
}

/// The layout encase writes of `value` for `space`, each of `names` marked in order by its
/// index `k`: the float [`mark`]`(k)`, or the word `k` where `word(k)`.
pub(super) fn marked_layout<T: ShaderType + WriteInto>(
    value: &T,
    space: Space,
    names: &[&str],
    word: impl Fn(u32) -> bool,
) -> (Vec<(String, usize)>, usize) {
    let markers: Vec<(&str, u32)> = (0u32..)
        .zip(names.iter().copied())
        .map(|(k, n)| (n, if word(k) { k } else { mark(k).to_bits() }))
        .collect();
    encase_layout(value, space, &markers)
}

/// The float marking member `k`.
pub(super) fn mark(k: u32) -> f32 {
    100.0 + k as f32
}

/// `LodUniform`'s layout, each member marked.
pub(super) fn marked_lod() -> (Vec<(String, usize)>, usize) {
    let lod = LodUniform {
        falloff_near: mark(0),
        falloff_far: mark(1),
        falloff_floor: mark(2),
        falloff_on: 3,
        fade_band: mark(4),
        thinning_from: mark(5),
        thinning_floor: mark(6),
        thinning_on: 7,
    };
    let names = [
        "falloff_near",
        "falloff_far",
        "falloff_floor",
        "falloff_on",
        "fade_band",
        "thinning_from",
        "thinning_floor",
        "thinning_on",
    ];
    marked_layout(&lod, Space::Storage, &names, |k| k == 3 || k == 7)
}

/// `ChunkUniform`'s layout, each member marked (`lod` by its first member).
fn marked_chunk() -> (Vec<(String, usize)>, usize) {
    let marked = ChunkUniform {
        origin: Vec3::splat(mark(0)),
        mesh_top: mark(1),
        base_color: Vec4::splat(mark(2)),
        tip_color: Vec4::splat(mark(3)),
        color_variation: mark(4),
        roughness: mark(5),
        wind_response: mark(6),
        tip_from: mark(7),
        lod: LodUniform {
            falloff_near: mark(8),
            ..Default::default()
        },
        wind_direction: Vec2::splat(mark(9)),
        wind_strength: mark(10),
        wind_frequency: mark(11),
        wind_speed: mark(12),
        bend_response: mark(13),
        alpha_cutoff: mark(14),
        textured: 15,
        fade_in_from: mark(16),
        fade_in_to: mark(17),
        fade_out_from: mark(18),
        fade_out_to: mark(19),
        impostor_half: Vec2::splat(mark(20)),
        impostor_center: Vec3::splat(mark(21)),
        impostor_views: 22,
        impostor_rows: 23,
        metallic: mark(24),
        reflectance: mark(25),
        emissive: Vec4::splat(mark(26)),
    };
    let names = [
        "origin",
        "mesh_top",
        "base_color",
        "tip_color",
        "color_variation",
        "roughness",
        "wind_response",
        "tip_from",
        "lod",
        "wind_direction",
        "wind_strength",
        "wind_frequency",
        "wind_speed",
        "bend_response",
        "alpha_cutoff",
        "textured",
        "fade_in_from",
        "fade_in_to",
        "fade_out_from",
        "fade_out_to",
        "impostor_half",
        "impostor_center",
        "impostor_views",
        "impostor_rows",
        "metallic",
        "reflectance",
        "emissive",
    ];
    marked_layout(&marked, Space::Uniform, &names, |k| {
        matches!(k, 15 | 22 | 23)
    })
}

/// `FrameUniform`'s layout, each member marked by its own value.
fn marked_frame() -> (Vec<(String, usize)>, usize) {
    let marked = FrameUniform {
        viewer: Vec3::splat(1.0),
        bends: 7,
        bend_min: Vec2::splat(2.0),
        bend_scale: 3.0,
    };
    let markers = [
        ("viewer", 1.0f32.to_bits()),
        ("bends", 7),
        ("bend_min", 2.0f32.to_bits()),
        ("bend_scale", 3.0f32.to_bits()),
    ];
    encase_layout(&marked, Space::Uniform, &markers)
}

/// The members (name, offset) and size of struct `name` in a module's types' `Debug` text.
pub(super) fn struct_layout(types: &str, name: &str) -> (Vec<(String, usize)>, usize) {
    // An imported struct's name is mangled (`NameX_naga_oil_mod_X...`).
    let start = [format!("\"{name}\""), format!("\"{name}X_naga_oil_mod_")]
        .iter()
        .find_map(|n| {
            types.find(&format!("name: Some({n}")).filter(|&at| {
                types[at..]
                    .split("inner: ")
                    .nth(1)
                    .is_some_and(|t| t.starts_with("Struct"))
            })
        })
        .unwrap_or_else(|| panic!("no struct {name}"));
    let body = &types[start..];
    let end = body.find("span: ").expect("a struct's span");
    let span = body[end + 6..]
        .split(|c: char| !c.is_ascii_digit())
        .next()
        .and_then(|s| s.parse().ok())
        .expect("a span");
    let members = body[..end]
        .split("StructMember { name: Some(\"")
        .skip(1)
        .map(|m| {
            let member = m.split('"').next().unwrap_or_default().to_string();
            let offset = m.split("offset: ").nth(1).unwrap_or_default();
            let digits: String = offset.chars().take_while(char::is_ascii_digit).collect();
            (member, digits.parse().expect("an offset"))
        })
        .collect();
    (members, span)
}

#[test]
fn every_permutation_composes_and_validates_with_the_uniform_layouts() {
    let mut cache = cache_with_library();
    let id = AssetId::from(Uuid::from_u128(u128::MAX));
    let shader = Shader::from_wgsl(include_str!("instanced.wgsl"), "instanced.wgsl");
    cache.set_shader(id, shader);
    let mut failed = Vec::new();
    let mut composed = Vec::new();
    for (k, defs) in permutations().iter().enumerate() {
        match cache.get(k, id, defs) {
            Ok(types) => composed.push(types),
            Err(e) => failed.push(format!("{defs:?}: {e:?}")),
        }
    }
    assert!(
        failed.is_empty(),
        "{} failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
    // 20 combinations of a class's own look's features, 40 of an asset surface's without
    // crossfades, 30 with them.
    assert_eq!(composed.len(), (20 + 40 + 30) * 17);
    let (chunk, frame, lod) = (marked_chunk(), marked_frame(), marked_lod());
    for types in &composed {
        assert_eq!(struct_layout(types, "Chunk"), chunk);
        assert_eq!(struct_layout(types, "Frame"), frame);
        assert_eq!(struct_layout(types, "Lod"), lod);
    }
}
