//! The loaders under hostile input, shared by `tests/hostile.rs` (proptest) and the cargo-fuzz
//! targets in `fuzz/` (included there by path): each function runs one loader — and, where the
//! file becomes geometry, that step too — on a text, and ignores the outcome; a panic or a
//! hang is the failure. `docs/hostile.md`.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The repository root: the first ancestor of this crate's folder holding `fixtures/`.
pub fn root() -> PathBuf {
    let mut dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    while !dir.join("fixtures").is_dir() {
        assert!(
            dir.pop(),
            "no fixtures/ above {}",
            env!("CARGO_MANIFEST_DIR")
        );
    }
    dir
}

/// A fixture's text.
pub fn fixture(path: &str) -> String {
    std::fs::read_to_string(root().join(path)).expect("fixture")
}

/// A folder of its own for one case's files.
pub fn scratch(tag: &str) -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "atelier-hostile-{}-{tag}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).expect("scratch");
    dir
}

/// A fabric file: parse, check, build the characteristics.
pub fn load_fabric(text: String) {
    let _ = atelier_fabric::Fabric::from_ron_str(&text, Path::new("hostile.ron"));
}

/// A pattern file: read, then grid it.
pub fn load_pattern(text: String) {
    let dir = scratch("pattern");
    let path = dir.join("p.ron");
    std::fs::write(&path, &text).expect("write");
    if let Ok(spec) = atelier_grid::pattern::load_pattern(&path) {
        let _ = atelier_grid::pattern::grid_pattern(&spec, atelier_grid::ImproveParams::default());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A DXF-AAMA pattern file: read, every piece planned (corners searched) and gridded, as
/// `atelier pattern` does (4 cm cells, to keep a case short).
pub fn load_dxf_pattern(text: String) {
    load_imported(&text, "dxf");
}

/// A FreeSewing-style SVG pattern file: read, every part unfolded, its V darts closed,
/// planned (corners searched) and gridded, as `atelier pattern` does (4 cm cells).
pub fn load_svg_pattern(text: String) {
    load_imported(&text, "svg");
}

/// A pattern file of extension `ext` through `atelier::patterns::import` at 4 cm cells.
fn load_imported(text: &str, ext: &str) {
    let dir = scratch(ext);
    let path = dir.join(format!("p.{ext}"));
    std::fs::write(&path, text).expect("write");
    let options = atelier_import::PanelOptions {
        spacing_cm: 4.0,
        ..atelier_import::PanelOptions::default()
    };
    let _ = atelier::patterns::import(&path, &options);
    std::fs::remove_dir_all(&dir).ok();
}

/// A small FreeSewing-style SVG: one part cut on the fold, with a V dart, a grain line and a
/// notch (the layout of `fixtures/patterns/freesewing/`).
pub const SVG: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="300mm" height="400mm" viewBox="0 0 300 400"><defs><g id="notch"><circle r="1"/></g></defs><g id="fs-container"><g id="fs-stack-x.front" transform="translate(20, 10)"><g id="fs-stack-x.front-part-x.front" transform="translate(0, 0)"><path class="fabric" d="M 0,0 L 0,300 L 200,300 C 210,200 210,100 200,0 L 120,0 L 110,80 L 100,0 z"/><path class="fabric sa" d="M -10,-10 L -10,310 L 210,310 L 210,-10 z"/><path class="note" marker-start="url(#cutonfoldFrom)" marker-end="url(#cutonfoldTo)" data-text="cutOnFoldAndGrainline" d="M 0,20 L 15,20 L 15,280 L 0,280"/><use x="200" y="150" xlink:href="#notch"/><text class="text-lg fill-current font-bold">front</text></g></g></g></svg>"##;

/// A garment file beside the skirt's patterns: read, grid every panel, pair the seams.
pub fn load_garment(text: String) {
    let dir = scratch("garment");
    for p in [
        "front_skirt.ron",
        "back_skirt_left.ron",
        "back_skirt_right.ron",
    ] {
        std::fs::copy(root().join("fixtures/patterns/dress").join(p), dir.join(p)).expect("copy");
    }
    let path = dir.join("g.ron");
    std::fs::write(&path, &text).expect("write");
    let _ = atelier_grid::pattern::load_garment(&path, atelier_grid::ImproveParams::default());
    std::fs::remove_dir_all(&dir).ok();
}

/// A body description: parse, then build the mannequin.
pub fn load_body(text: String) {
    use atelier_body::description::BodyDescription;
    if let Ok(d) = BodyDescription::parse(&text, Path::new("hostile.ron")) {
        let _ = atelier_body::Mannequin::from_description(&d, &d.sizes);
    }
}

/// A motion file against the standard mannequin.
pub fn load_motion(text: String, mannequin: &atelier_body::Mannequin) {
    let dir = scratch("motion");
    let path = dir.join("m.ron");
    std::fs::write(&path, &text).expect("write");
    let _ = atelier_body::motion::Motion::load(&path, mannequin);
    std::fs::remove_dir_all(&dir).ok();
}

/// The standard mannequin, built once.
pub fn mannequin() -> &'static atelier_body::Mannequin {
    use atelier_body::description::BodyDescription;
    static M: std::sync::OnceLock<atelier_body::Mannequin> = std::sync::OnceLock::new();
    M.get_or_init(|| {
        let d = BodyDescription::load(&root().join("fixtures/bodies/jis_9ar.ron")).expect("body");
        atelier_body::Mannequin::from_description(&d, &d.sizes).expect("mannequin")
    })
}

/// A string-fit observation file.
pub fn load_observations(text: String) {
    let _ = atelier_fit::observation::Observations::parse(&text, Path::new("hostile.ron"));
}

/// A synthetic chain's observation file (three shapes), made once.
pub fn observations_fixture() -> &'static str {
    use atelier_fit::synthetic::{Object, SyntheticOptions, observe};
    static T: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    T.get_or_init(|| {
        let options = SyntheticOptions {
            shapes: 3,
            ..SyntheticOptions::default()
        };
        observe(Object::Chain, &options)
            .expect("observed")
            .0
            .to_ron()
    })
}

/// A scenario file.
pub fn load_scenario(text: String) {
    let _ = atelier::scenario::Scenario::parse(&text, Path::new("hostile.ron"));
}

/// A mesh, as OBJ and as PLY.
pub fn load_mesh(text: String) {
    let opts = atelier_body::io::LoadOptions::default();
    let _ = atelier_body::io::parse_obj(&text, Path::new("hostile.obj"), &opts);
    let _ = atelier_body::io::parse_ply(&text, Path::new("hostile.ply"), &opts);
}

pub const OBJ: &str =
    "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
pub const PLY: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";

/// Cloth observations for `atelier fit` (a cantilever profile; the fit runs, its outputs go
/// to a scratch folder).
pub fn load_cloth_observations(text: String) {
    let dir = scratch("cloth");
    std::fs::copy(
        root().join("fixtures/fabrics/cotton_broad.ron"),
        dir.join("base.ron"),
    )
    .expect("copy");
    let path = dir.join("o.ron");
    std::fs::write(&path, &text).expect("write");
    let _ = atelier::fit::fit_cloth(&path, &dir.join("out"));
    std::fs::remove_dir_all(&dir).ok();
}

pub const CLOTH: &str = r#"ClothObservations(
    name: "strips",
    provenance: "hostile-input test",
    base: "base.ron",
    cantilevers: [(direction: Warp, overhang: 0.04, points: [(0.01, 0.0099, 0.001), (0.02, 0.0195, 0.004), (0.03, 0.0285, 0.009), (0.04, 0.037, 0.015)])],
)"#;

/// A try-on start pose (`--pose`, the format of `fitted_pose.ron`): parse and check.
pub fn load_pose(text: String) {
    if let Ok(pose) = atelier_files::files::parse_ron::<atelier_tryon::pose::PoseFile>(
        &text,
        Path::new("hostile_pose.ron"),
    ) {
        let _ = pose.check();
    }
}

/// A photograph and a mask (PNG bytes): read the photograph, then the mask against its size and
/// against a wrong size, and segment the photograph.
pub fn load_picture(bytes: Vec<u8>) {
    let dir = scratch("picture");
    let path = dir.join("p.png");
    std::fs::write(&path, &bytes).expect("write");
    if let Ok(photo) = atelier_tryon::image::load_photo(&path) {
        let _ = atelier_tryon::image::load_mask(&path, (photo.width, photo.height));
        let _ = atelier_tryon::image::load_mask(&path, (photo.width + 1, photo.height));
        if photo.width * photo.height <= 1 << 20 {
            let _ = atelier_tryon::image::segment_plain_background(&photo, 40);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
