//! Layer files: parsing, checking, writing and describing layers.

use super::*;
use crate::look::{ClassLook, InstancedShadows};

/// The layer of `d` with default handles and no names.
fn plain(d: &LayerDescription) -> ScatterLayer {
    d.to_layer(&NamedAssets::default(), &mut Placeholders)
        .unwrap()
}

/// Handles that record what a file asks for; every image is `image`.
#[derive(Default)]
struct Recorder {
    meshes: Vec<MeshDescription>,
    materials: Vec<MaterialDescription>,
    images: Vec<String>,
    gltfs: Vec<String>,
    image: Handle<Image>,
}

impl Recorder {
    /// Whether nothing was asked for.
    fn nothing(&self) -> bool {
        self.meshes.is_empty()
            && self.materials.is_empty()
            && self.images.is_empty()
            && self.gltfs.is_empty()
    }
}

impl LayerHandles for Recorder {
    fn mesh(&mut self, mesh: &MeshDescription) -> Handle<Mesh> {
        self.meshes.push(mesh.clone());
        Handle::default()
    }

    fn material(&mut self, material: &MaterialDescription) -> Handle<StandardMaterial> {
        self.materials.push(material.clone());
        Handle::default()
    }

    fn image(&mut self, path: &str) -> Handle<Image> {
        self.images.push(path.to_string());
        self.image.clone()
    }

    #[cfg(feature = "gltf")]
    fn gltf(&mut self, path: &str) -> Handle<bevy::gltf::Gltf> {
        self.gltfs.push(path.to_string());
        Handle::default()
    }
}

const MEADOW: &str = r#"(
    tile_size: 4.0,
    seed: 9,
    chunk_size: 16.0,
    load_distance: 48.0,
    unload_distance: 64.0,
    falloff: (20.0, 60.0),
    classes: [
        (density: Constant(0.4), mesh: Cone(radius: 0.5, height: 2.0), material: Color(0.1, 0.5, 0.1)),
        (density: Noise(seed: 1, frequency: 0.1, octaves: 3, base: 0.5, amplitude: 0.5, scale: 0.2),
         mesh: Sphere(radius: 0.3), material: Color(0.6, 0.2, 0.2), scale: 1.5),
    ],
)"#;

#[test]
fn a_layer_file_writes_and_reads_back_the_same() {
    let with_all = MEADOW.replace(
        "falloff: (20.0, 60.0),",
        "falloff: (20.0, 60.0), falloff_floor: 0.25, exclusion: Image(path: \"roads.png\", min: (0.0, 0.0), size: (8.0, 8.0), scale: 1.0),",
    );
    let with_all = with_all.replace(
        "classes: [",
        r#"classes: [
        (density: Image(path: "m.png", min: (0.0, 0.0), size: (8.0, 8.0), scale: 2.0),
         mesh: Blade(width: 0.1, height: 0.6), material: Instanced(tip: (0.3, 0.5, 0.1), tip_from: 0.8, shadows: Within(30.0), texture: Some("fern.png"), alpha_cutoff: 0.3),
         lod: (mesh: Blade(width: 0.1, height: 0.3), material: Instanced(), distance: 40.0)),
        (density: Constant(1.0), mesh: Path("a.glb#Mesh0/Primitive0"), material: Path("a.glb#Material0")),"#,
    );
    let d = LayerDescription::from_ron(&with_all).unwrap();
    assert_eq!(d.classes.len(), 4);
    let Some(MaterialDescription::Instanced(m)) = &d.classes[0].material else {
        panic!("the first class is instanced");
    };
    let mut loaded = Vec::new();
    let material = m.to_material(|path| {
        loaded.push(path.to_string());
        Handle::default()
    });
    assert_eq!(material.shadows, InstancedShadows::Within(30.0));
    assert_eq!(
        (loaded, material.alpha_cutoff),
        (vec!["fern.png".to_string()], 0.3)
    );
    let text = d.to_ron().unwrap();
    assert!(!text.contains("Some("), "{text}");
    assert_eq!(LayerDescription::from_ron(&text).unwrap(), d);
}

#[test]
fn parses_a_layer_file() {
    let d = LayerDescription::from_ron(MEADOW).unwrap();
    assert_eq!(d.classes.len(), 2);
    assert_eq!(d.classes[1].scale, 1.5);
    assert_eq!(d.classes[0].scale_variation, 0.2);
    let layer = plain(&d);
    assert_eq!(layer.tile_size, 4.0);
    assert_eq!(layer.streaming.load_distance, 48.0);
    assert_eq!(layer.falloff, Some(Falloff::new(20.0, 60.0)));
    assert!(layer.exclusion.is_none());
    let floored = MEADOW.replace(
        "falloff: (20.0, 60.0),",
        "falloff: (20.0, 60.0), falloff_floor: 0.25,",
    );
    let floored = plain(&LayerDescription::from_ron(&floored).unwrap());
    assert_eq!(floored.falloff.map(|f| f.floor), Some(0.25));
    let excluded = MEADOW.replace(
        "falloff: (20.0, 60.0),",
        "falloff: (20.0, 60.0), exclusion: Image(path: \"roads.png\", min: (0.0, 0.0), size: (8.0, 8.0), scale: 1.0),",
    );
    let mut loads = Recorder::default();
    let layer = LayerDescription::from_ron(&excluded)
        .unwrap()
        .to_layer(&NamedAssets::default(), &mut loads)
        .unwrap();
    assert!(matches!(layer.exclusion, Some(LayerDensity::Image(_))));
    assert_eq!(loads.images, ["roads.png"]);
}

#[test]
fn instanced_classes_in_a_layer_file() {
    let text = MEADOW.replace(
        "classes: [",
        "classes: [(density: Constant(30.0), mesh: Blade(width: 0.08, height: 0.6), \
         material: Instanced(tip: (0.3, 0.5, 0.1), fade_band: 0.2), scale_variation: 0.3), \
         (density: Constant(5.0), mesh: Cuboid(size: (0.1, 0.1, 0.1)), material: Instanced()),",
    );
    let d = LayerDescription::from_ron(&text).unwrap();
    let mut loads = Recorder::default();
    let layer = d.to_layer(&NamedAssets::default(), &mut loads).unwrap();
    assert_eq!(loads.materials.len(), 2, "entity classes only");
    let ClassLook::Instanced(look) = &layer.classes[0].look else {
        panic!("{:?}", layer.classes[0].look);
    };
    assert_eq!(look.material.tip_color, Color::linear_rgb(0.3, 0.5, 0.1));
    assert_eq!(look.material.fade_band, 0.2);
    let defaults = InstancedShading::default();
    assert_eq!(look.material.roughness, defaults.roughness);
    assert_eq!(layer.classes[0].scale_variation, 0.3);
    let ClassLook::Instanced(plain) = &layer.classes[1].look else {
        panic!("{:?}", layer.classes[1].look);
    };
    let base = defaults.base_color.to_linear();
    let read = plain.material.base_color.to_linear();
    assert!((base.green - read.green).abs() < 1e-6, "{base:?} {read:?}");
    let blade = d.classes[0].mesh.as_ref().unwrap().primitive().unwrap();
    let (_, hi) = crate::look::check_instanced_mesh(&blade).unwrap().unwrap();
    assert!((hi.y - 0.6).abs() < 1e-6);
}

#[test]
fn rejects_bad_files_with_reasons() {
    let err = |t: &str| LayerDescription::from_ron(t).unwrap_err().to_string();
    assert!(err("(classes: [").contains("invalid layer file"));
    assert!(err("(classes: [])").contains("at least one class"));
    let bad_tile = MEADOW.replace("tile_size: 4.0", "tile_size: -1.0");
    assert!(err(&bad_tile).contains("tile_size"));
    let inverted = MEADOW.replace("unload_distance: 64.0", "unload_distance: 10.0");
    assert!(err(&inverted).contains("unload_distance"));
    let far = MEADOW.replace("load_distance: 48.0", "load_distance: 1e300");
    assert!(err(&far).contains("more than 256 chunks"), "{}", err(&far));
    let zero = MEADOW.replace("load_distance: 48.0", "load_distance: 0.0");
    assert!(err(&zero).contains("load_distance 0 must be positive"));
}

#[test]
fn numbers_out_of_range_and_unknown_fields_are_refused_by_name() {
    let err = |t: &str| LayerDescription::from_ron(t).unwrap_err().to_string();
    // Numbers that loaded and then streamed nothing, streamed without end or drew garbage.
    for (from, to, words) in [
        (
            "tile_size: 4.0",
            "tile_size: 1e300",
            "tile_size 1e300 must be between 1e-9 and 1e12",
        ),
        (
            "tile_size: 4.0",
            "tile_size: 1e-300",
            "tile_size 1e-300 must be between",
        ),
        (
            "chunk_size: 16.0",
            "chunk_size: 1e300",
            "chunk_size 1e300 must be between",
        ),
        (
            "(20.0, 60.0)",
            "(60.0, 20.0)",
            "falloff end 20 must be finite and at least 60",
        ),
        (
            "(20.0, 60.0)",
            "(NaN, 60.0)",
            "falloff start NaN must be finite and at least 0",
        ),
        (
            "Constant(0.4)",
            "Constant(NaN)",
            "class 0: density NaN must be finite and at least 0",
        ),
        (
            "Constant(0.4)",
            "Constant(-1.0)",
            "class 0: density -1 must be",
        ),
        (
            "Constant(0.4)",
            "Constant(1e400)",
            "class 0: density inf must be",
        ),
        (
            "octaves: 3",
            "octaves: 1000",
            "class 1: noise octaves 1000 must be between 1 and 16",
        ),
        (
            "frequency: 0.1",
            "frequency: 0.0",
            "class 1: noise frequency 0 must be positive",
        ),
        (
            "radius: 0.5",
            "radius: NaN",
            "class 0: mesh radius NaN must be positive and at most 1e6",
        ),
        (
            "height: 2.0",
            "height: 1e30",
            "class 0: mesh height 1e30 must be",
        ),
        (
            "scale: 1.5",
            "scale: -1.5",
            "class 1: scale -1.5 must be positive",
        ),
        (
            "Color(0.1, 0.5, 0.1)",
            "Color(NaN, 0.5, 0.1)",
            "class 0: colour NaN must be",
        ),
        (
            "seed: 9,",
            "seed: 9, wobble: 3,",
            "Unexpected field named `wobble`",
        ),
        (
            "scale: 1.5)",
            "scale: 1.5, lod_distence: 3.0)",
            "Unexpected field named `lod_distence`",
        ),
    ] {
        let bad = MEADOW.replace(from, to);
        assert_ne!(bad, MEADOW, "{from}");
        assert!(err(&bad).contains(words), "{to}: {}", err(&bad));
    }
    let class =
        "(density: Constant(0.1), mesh: Sphere(radius: 0.3), material: Color(0.6, 0.2, 0.2)),";
    let many = MEADOW.replacen(
        "classes: [",
        &format!("classes: [{}", class.repeat(1 << 16)),
        1,
    );
    assert!(err(&many).contains("65538 classes, more than 65536"));
}

/// A handle made in code (no asset path).
fn uuid<A: Asset>(n: u128) -> Handle<A> {
    Handle::Uuid(bevy::asset::uuid::Uuid::from_u128(n), default())
}

/// A layer built in code as a game does it: named meshes, materials and ground.
fn code_layer(names: &NamedAssets, map: &Handle<Image>) -> ScatterLayer {
    let (bush, far, leaf) = (
        uuid::<Mesh>(6),
        uuid::<Mesh>(7),
        uuid::<StandardMaterial>(8),
    );
    names.insert_mesh("bush", bush.clone());
    names.insert_mesh("bush far", far.clone());
    names.insert_material("leaf", leaf.clone());
    let ground = HeightSource::Function(std::sync::Arc::new(|p: Vec2| 0.1 * p.x));
    names.insert_height("terrain", &ground);
    let painted = LayerDensity::Image(GroundMap {
        image: map.clone(),
        min: Vec2::splat(-8.0),
        size: Vec2::splat(16.0),
        scale: 3.0,
    });
    let noise = rwt_core::density::NoiseParams {
        seed: 4,
        frequency: 0.1,
        octaves: 2,
        base: 0.3,
        amplitude: 0.5,
        scale: 1.0,
    };
    let mut flower = ScatterClass::instanced(
        painted,
        bush.clone(),
        InstancedShading {
            tip_from: 0.8,
            shadows: InstancedShadows::Off,
            ..default()
        },
    );
    flower.scale = 0.5;
    let tree = ScatterClass::new(
        LayerDensity::Noise(NoiseDensity::new(noise)),
        bush,
        leaf.clone(),
    )
    .with_lod(far, leaf, 50.0);
    let mut layer = ScatterLayer::new(vec![flower, tree])
        .with_seed(11)
        .with_tile_size(6.0)
        .with_falloff_floor(10.0, 40.0, 0.3)
        .with_height(ground)
        .with_height_range(-2.0, 9.0)
        .with_max_slope(0.7);
    layer.exclusion = Some(LayerDensity::Constant(0.0));
    layer
}

#[test]
fn a_layer_built_in_code_describes_itself_and_reads_back_the_same() {
    let names = NamedAssets::default();
    let map = uuid::<Image>(9);
    let layer = code_layer(&names, &map);
    let saved = |h: &Handle<Image>| (h.id() == map.id()).then(|| "./flowers.png".to_string());
    let d = LayerDescription::describe(&layer, &names, saved).unwrap();
    assert_eq!(
        d.classes[1].mesh,
        Some(MeshDescription::Named("bush".into()))
    );
    assert_eq!(d.ground, Some(HeightDescription::Named("terrain".into())));
    let text = d.to_ron().unwrap();
    let read = LayerDescription::from_ron(&text).unwrap();
    assert_eq!(read, d, "{text}");
    let mut loads = Recorder {
        image: map.clone(),
        ..Recorder::default()
    };
    let back = read.to_layer(&names, &mut loads).unwrap();
    assert_eq!(loads.images, ["./flowers.png"]);
    assert!(
        loads.meshes.is_empty() && loads.materials.is_empty(),
        "only named ones"
    );
    let ClassLook::Mesh { material, .. } = &back.classes[1].look else {
        panic!("{:?}", back.classes[1].look);
    };
    assert_eq!(Some(material.id()), names.material("leaf").map(|h| h.id()));
    let lod = back.classes[1].lod.as_ref().unwrap();
    assert_eq!((lod.distance, lod.crossfade), (50.0, 5.0));
    assert_eq!(names.height_name(&back.height).as_deref(), Some("terrain"));
    assert_eq!(back.falloff, layer.falloff);
    assert_eq!(back.streaming, layer.streaming);
    // The layer read back describes itself the same way: nothing was lost on the way.
    let again = LayerDescription::describe(&back, &names, saved).unwrap();
    assert_eq!(again, d);
}

#[test]
fn what_a_file_cannot_name_is_a_typed_error() {
    let names = NamedAssets::default();
    let map = uuid::<Image>(9);
    let layer = code_layer(&names, &map);
    let err = LayerDescription::describe(&layer, &names, |_| None).unwrap_err();
    assert!(
        matches!(
            &err,
            LayerFileError::NotDescribable {
                part: LayerPart::Class(0),
                what: Undescribable::Image(_)
            }
        ),
        "{err}"
    );
    let mut unnamed = layer.clone();
    unnamed.classes[1].look = ClassLook::Mesh {
        mesh: uuid(99),
        material: names.material("leaf").unwrap(),
    };
    let err = LayerDescription::describe(&unnamed, &names, |_| Some("m.png".into())).unwrap_err();
    assert!(err.to_string().contains("class 1: mesh"), "{err}");
    let mut elsewhere = layer.clone();
    elsewhere.height = HeightSource::Function(std::sync::Arc::new(|_| 0.0));
    let err = LayerDescription::describe(&elsewhere, &names, |_| Some("m.png".into())).unwrap_err();
    assert!(err.to_string().contains("the ground"), "{err}");
    let mut custom = layer.clone();
    custom.classes[0].density =
        LayerDensity::Custom(std::sync::Arc::new(rwt_core::density::Constant(1.0)));
    let err = LayerDescription::describe(&custom, &names, |_| Some("m.png".into())).unwrap_err();
    assert!(err.to_string().contains("custom density"), "{err}");
    // A far material is `Instanced()` exactly when the class is instanced.
    for (class, far) in [
        ("Color(0.6, 0.2, 0.2)", "Instanced()"),
        ("Instanced()", "Color(0.1, 0.1, 0.1)"),
    ] {
        let text = MEADOW.replace(
            "material: Color(0.6, 0.2, 0.2), scale: 1.5",
            &format!("material: {class}, lod: (mesh: Sphere(radius: 0.1), material: {far}, distance: 30.0)"),
        );
        let err = LayerDescription::from_ron(&text).unwrap_err();
        assert!(
            matches!(
                &err,
                LayerFileError::Invalid(InvalidLayer::FarMaterial { class: 1 })
            ),
            "{err}"
        );
    }
    // A file naming what the game did not register does not load.
    let text = MEADOW.replace("mesh: Sphere(radius: 0.3)", "mesh: Named(\"oak\")");
    let err = LayerDescription::from_ron(&text)
        .unwrap()
        .to_layer(&names, &mut Placeholders)
        .unwrap_err();
    assert!(
        matches!(&err, LayerFileError::UnknownName { kind: NamedKind::Mesh, name } if name == "oak"),
        "{err}"
    );
}

#[test]
fn ground_stances_and_clumps_read_back_the_same() {
    use crate::ground::SurfacePolicy;
    use rwt_core::clumps::{ClumpKernel, ClumpParams, Clumps};
    let names = NamedAssets::default();
    names.insert_mesh("moss", uuid::<Mesh>(3));
    names.insert_material("green", uuid::<StandardMaterial>(4));
    let params = ClumpParams {
        seed: 4,
        clumps: 0.002,
        per_clump: 20.0,
        radius: 2.5,
        kernel: ClumpKernel::Matern,
    };
    let density = LayerDensity::Clumps(Clumps::new(params).unwrap());
    let collider: crate::look::InstanceInserter = std::sync::Arc::new(|_| {});
    names.insert_inserter("collider", &collider);
    let mut class = ScatterClass::new(density, uuid::<Mesh>(3), uuid::<StandardMaterial>(4))
        .with_stance(0.75, 0.05)
        .with_pick_bounds(Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 2.0, 0.5));
    class.promotion = Some(crate::Promotion {
        distance: 12.0,
        insert: collider.clone(),
    });
    let layer = ScatterLayer::new(vec![class])
        .on_surfaces(SurfacePolicy::Every)
        .with_per_area(false)
        .with_keep_out("trees", [1.2, 0.0]);
    let d = LayerDescription::describe(&layer, &names, |_| None).unwrap();
    assert_eq!(d.ground, Some(HeightDescription::Surfaces));
    let text = d.to_ron().unwrap();
    let parts = [
        "Surfaces",
        "Every",
        "per_area: false",
        "align: 0.75",
        "Matern",
        "collider",
        "trees",
    ];
    for part in parts {
        assert!(text.contains(part), "{part} missing from {text}");
    }
    let read = LayerDescription::from_ron(&text).unwrap();
    assert_eq!(read, d);
    let mut loads = Recorder::default();
    let back = read.to_layer(&names, &mut loads).unwrap();
    assert!(loads.nothing(), "everything by name");
    assert!(matches!(back.height, HeightSource::Surfaces));
    assert_eq!(
        (back.surfaces, back.per_area),
        (SurfacePolicy::Every, false)
    );
    assert_eq!(back.keep_out, layer.keep_out);
    assert_eq!(back.classes[0].stance, layer.classes[0].stance);
    let LayerDensity::Clumps(c) = &back.classes[0].density else {
        panic!("{:?}", back.classes[0].density);
    };
    assert_eq!(c.params(), params);
    assert_eq!(back.classes[0].pick_bounds, layer.classes[0].pick_bounds);
    let promotion = back.classes[0].promotion.as_ref().unwrap();
    assert_eq!(promotion.distance, 12.0);
    assert!(std::sync::Arc::ptr_eq(&promotion.insert, &collider));
    // Clump parameters out of range are refused when the file is read.
    let bad = text.replace("radius: 2.5", "radius: -1.0");
    assert!(matches!(
        LayerDescription::from_ron(&bad),
        Err(LayerFileError::Invalid(InvalidLayer::Clumps(_)))
    ));
}

#[test]
fn keep_outs_by_entity_custom_grounds_and_unnamed_inserters_are_reported() {
    let names = NamedAssets::default();
    names.insert_mesh("moss", uuid::<Mesh>(3));
    names.insert_material("green", uuid::<StandardMaterial>(4));
    let class = ScatterClass::new(
        LayerDensity::Constant(1.0),
        uuid::<Mesh>(3),
        uuid::<StandardMaterial>(4),
    );
    let kept = ScatterLayer::new(vec![class.clone()]).with_keep_out(Entity::PLACEHOLDER, [1.0]);
    let custom = ScatterLayer::new(vec![class]).with_height(HeightSource::Custom(
        std::sync::Arc::new(crate::ground::FlatGround(1.0)),
    ));
    // A promotion whose inserter has no name cannot be written either.
    let mut promoted = custom.clone();
    promoted.height = HeightSource::Constant(0.0);
    promoted.classes[0].promotion = Some(crate::Promotion {
        distance: 3.0,
        insert: std::sync::Arc::new(|_| {}),
    });
    let cases = [
        (kept, Undescribable::KeepOut),
        (custom, Undescribable::CustomGround),
        (promoted, Undescribable::PromotionInserter),
    ];
    for (layer, what) in cases {
        let e = LayerDescription::describe(&layer, &names, |_| None).unwrap_err();
        assert!(
            matches!(&e, LayerFileError::NotDescribable { what: w, .. } if *w == what),
            "{e}"
        );
    }
}

#[test]
fn formats_place_the_lattice_and_unknown_ones_are_refused() {
    // A file without `format` was written before seeded lattices: its layer keeps its
    // places on the aligned lattice.
    let old = LayerDescription::from_ron(MEADOW).unwrap();
    assert_eq!((old.format, old.lattice()), (1, Lattice::Aligned));
    assert_eq!(plain(&old).lattice, Lattice::Aligned);
    // Format 2 lays the seed's own lattice unless the file says otherwise.
    let new = MEADOW.replacen('(', "(format: 2,", 1);
    let new = LayerDescription::from_ron(&new).unwrap();
    assert_eq!(plain(&new).lattice, Lattice::Seeded);
    let kept = MEADOW.replacen('(', "(format: 2, lattice: Aligned,", 1);
    let kept = LayerDescription::from_ron(&kept).unwrap();
    assert_eq!(plain(&kept).lattice, Lattice::Aligned);
    // Described layers are written in this format, with their lattice, and read back so.
    let names = NamedAssets::default();
    let map = uuid::<Image>(9);
    let saved = |_: &Handle<Image>| Some("./flowers.png".to_string());
    for lattice in [Lattice::Aligned, Lattice::Seeded] {
        let layer = code_layer(&names, &map).with_lattice(lattice);
        let described = LayerDescription::describe(&layer, &names, saved);
        let text = described.unwrap().to_ron().unwrap();
        let back = LayerDescription::from_ron(&text).unwrap();
        assert_eq!(
            (back.format, back.lattice()),
            (LAYER_FORMAT, lattice),
            "{text}"
        );
    }
    for format in [0, LAYER_FORMAT + 1] {
        let text = MEADOW.replacen('(', &format!("(format: {format},"), 1);
        let e = LayerDescription::from_ron(&text).unwrap_err();
        assert!(
            matches!(e, LayerFileError::Invalid(InvalidLayer::Format { found, .. }) if found == format),
            "{e}"
        );
        assert!(e.to_string().contains(&format!("format {format}")), "{e}");
    }
}

const FOREST: &str = r#"(classes: [
    (density: Constant(0.01), asset: (path: "trees/oak.glb#Scene0", lods: [30.0, 90.0], wind_response: 0.05)),
    (density: Constant(0.02), asset: "rocks/boulder.glb", scale: 2.0),
])"#;

#[cfg(feature = "gltf")]
#[test]
fn asset_classes_in_a_layer_file() {
    use crate::look::asset::AssetRoot;
    let d = LayerDescription::from_ron(FOREST).unwrap();
    let mut loads = Recorder::default();
    let layer = d.to_layer(&NamedAssets::default(), &mut loads).unwrap();
    // The files load without their labels; the labels pick the part.
    assert_eq!(loads.gltfs, ["trees/oak.glb", "rocks/boulder.glb"]);
    assert!(loads.meshes.is_empty() && loads.materials.is_empty());
    let looks: Vec<_> = layer
        .classes
        .iter()
        .map(|c| match &c.look {
            ClassLook::Asset(look) => look.clone(),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(looks[0].root, AssetRoot::Scene(0));
    assert_eq!(looks[0].lods.distances, [30.0, 90.0]);
    assert_eq!(looks[0].wind_response, 0.05);
    assert!(looks[0].collider);
    // The path alone: every other field at the look's default.
    let plain = crate::look::asset::AssetLook::new(Handle::default());
    assert_eq!(looks[1].root, AssetRoot::File);
    assert_eq!(
        (&looks[1].lods, looks[1].fade_band, looks[1].shadows),
        (&plain.lods, plain.fade_band, plain.shadows)
    );
    assert_eq!(layer.classes[1].scale, 2.0);
    // Written back in full, read back the same.
    let text = d.to_ron().unwrap();
    assert!(text.contains("path: \"rocks/boulder.glb\""), "{text}");
    assert_eq!(LayerDescription::from_ron(&text).unwrap(), d);
}

#[test]
fn an_asset_class_has_nothing_else_to_look_like() {
    let with = |class: &str| format!("(classes: [(density: Constant(1.0), {class})])");
    for class in [
        "asset: \"a.glb\", mesh: Sphere(radius: 1.0)",
        "asset: \"a.glb\", material: Color(1.0, 1.0, 1.0)",
        "asset: \"a.glb\", lod: (mesh: Sphere(radius: 1.0), material: Color(1.0, 1.0, 1.0), distance: 9.0)",
        "mesh: Sphere(radius: 1.0)",
        "material: Color(1.0, 1.0, 1.0)",
        "scale: 2.0",
    ] {
        let err = LayerDescription::from_ron(&with(class)).unwrap_err();
        assert!(
            matches!(
                err,
                LayerFileError::Invalid(InvalidLayer::ClassLook { class: 0 })
            ),
            "{class}: {err}"
        );
    }
    for (class, field) in [
        (
            "asset: (path: \"a.glb\", lods: [10.0, -1.0])",
            "asset lod 1",
        ),
        (
            "asset: (path: \"a.glb\", crossfade: 2.0)",
            "asset crossfade",
        ),
        (
            "asset: (path: \"a.glb\", wind_response: inf)",
            "asset wind_response",
        ),
        (
            "asset: (path: \"a.glb\", shadows: Within(-3.0))",
            "asset shadows within",
        ),
    ] {
        let err = LayerDescription::from_ron(&with(class)).unwrap_err();
        let LayerFileError::Invalid(InvalidLayer::Number { field: named, .. }) = &err else {
            panic!("{class}: {err}");
        };
        assert_eq!(named, &format!("class 0: {field}"));
    }
    // Unknown fields of an asset are refused, in either form's place.
    let err =
        LayerDescription::from_ron(&with("asset: (path: \"a.glb\", lod: [1.0])")).unwrap_err();
    assert!(matches!(err, LayerFileError::Parse(_)), "{err}");
    let err = LayerDescription::from_ron(&with("asset: 3")).unwrap_err();
    assert!(matches!(err, LayerFileError::Parse(_)), "{err}");
}

#[cfg(not(feature = "gltf"))]
#[test]
fn without_the_gltf_feature_an_asset_class_is_a_typed_error() {
    let d = LayerDescription::from_ron(FOREST).unwrap();
    let err = d
        .to_layer(&NamedAssets::default(), &mut Placeholders)
        .unwrap_err();
    assert!(matches!(err, LayerFileError::NoGltf { class: 0 }), "{err}");
}
