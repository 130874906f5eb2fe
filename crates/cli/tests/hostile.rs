//! Hostile input (issue 10): every loader fed random and mutated files never panics and never
//! hangs. Each property takes a real fixture (or random bytes), applies a handful of mutations —
//! a byte flipped, a span deleted, a token inserted (brackets, quotes, NaN, huge and negative
//! numbers…), the file cut short, or one of its numbers replaced by such a token — and runs the
//! loader (and for patterns and bodies the step that turns the file into geometry) on its own
//! thread: it must return, Ok or a typed error, within [`LIMIT`] and without panicking.
//! `PROPTEST_CASES` sets the number of cases (default 48 per loader, a few seconds in all);
//! `docs/hostile.md` lists the loaders and the cargo-fuzz targets for longer runs.

mod loaders;

use std::sync::mpsc;
use std::time::Duration;

use loaders::*;
use proptest::prelude::*;

/// The longest a loader may take on one input.
const LIMIT: Duration = Duration::from_secs(20);

/// Tokens a hostile file might hold.
const TOKENS: [&str; 24] = [
    "NaN",
    "inf",
    "-inf",
    "-1",
    "0",
    "1e308",
    "-1e308",
    "1e-320",
    "99999999",
    "4294967297",
    "18446744073709551616",
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    "\"",
    ":",
    "Some(",
    "None",
    "\u{0}",
    "é",
];

/// One edit of a text.
#[derive(Clone, Debug)]
enum Edit {
    /// Replace the byte at (position mod length) by this one.
    Flip(usize, u8),
    /// Delete up to `len` bytes from (position mod length).
    Delete(usize, usize),
    /// Insert a token at (position mod length).
    Insert(usize, usize),
    /// Cut the text at (position mod length).
    Truncate(usize),
    /// Replace the (k mod count)-th number of the text by a token.
    Number(usize, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Edit::Flip(p, b)),
        (any::<usize>(), 1usize..40).prop_map(|(p, n)| Edit::Delete(p, n)),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(p, t)| Edit::Insert(p, t)),
        any::<usize>().prop_map(Edit::Truncate),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(k, t)| Edit::Number(k, t)),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(k, t)| Edit::Number(k, t)),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(k, t)| Edit::Number(k, t)),
    ]
}

/// The byte spans of the numbers in `text`.
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if text[i].is_ascii_digit() {
            let start = if i > 0 && text[i - 1] == b'-' {
                i - 1
            } else {
                i
            };
            let mut j = i;
            while j < text.len()
                && (text[j].is_ascii_digit() || matches!(text[j], b'.' | b'e' | b'E' | b'_'))
            {
                j += 1;
            }
            spans.push((start, j));
            i = j;
        } else {
            i += 1;
        }
    }
    spans
}

/// `text` with `edits` applied in turn (as bytes; the result read back lossily as UTF-8).
fn mutate(text: &str, edits: &[Edit]) -> String {
    let mut b = text.as_bytes().to_vec();
    for e in edits {
        let at = |p: usize, len: usize| if len == 0 { 0 } else { p % len };
        match *e {
            Edit::Flip(p, byte) => {
                if !b.is_empty() {
                    let i = at(p, b.len());
                    b[i] = byte;
                }
            }
            Edit::Delete(p, n) => {
                let i = at(p, b.len());
                let j = (i + n).min(b.len());
                b.drain(i..j);
            }
            Edit::Insert(p, t) => {
                let i = at(p, b.len() + 1);
                b.splice(i..i, TOKENS[t].bytes());
            }
            Edit::Truncate(p) => {
                let i = at(p, b.len() + 1);
                b.truncate(i);
            }
            Edit::Number(k, t) => {
                let spans = numbers(&b);
                if !spans.is_empty() {
                    let (i, j) = spans[k % spans.len()];
                    b.splice(i..j, TOKENS[t].bytes());
                }
            }
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

/// Run `load` on its own thread: it must return within [`LIMIT`] without panicking.
fn guarded(what: &str, input: &str, load: impl FnOnce() + Send + 'static) {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(load));
        let _ = tx.send(r.is_ok());
    });
    match rx.recv_timeout(LIMIT) {
        Ok(true) => {}
        Ok(false) => panic!("{what} panicked on:\n{input}"),
        Err(_) => panic!("{what} did not return within {LIMIT:?} on:\n{input}"),
    }
}

fn cases() -> ProptestConfig {
    ProptestConfig {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(48),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(cases())]

    #[test]
    fn fabric_files(edits in prop::collection::vec(edit(), 1..6), which in 0usize..3) {
        let base = fixture(["fixtures/fabrics/cotton_broad.ron", "fixtures/fabrics/denim.ron",
            "fixtures/fabrics/silk.ron"][which]);
        let text = mutate(&base, &edits);
        let t = text.clone();
        guarded("the fabric loader", &text, move || load_fabric(t));
    }

    #[test]
    fn pattern_files(edits in prop::collection::vec(edit(), 1..6), which in 0usize..3) {
        let base = fixture(["fixtures/patterns/square.ron", "fixtures/patterns/flared_skirt_panel.ron",
            "fixtures/patterns/dress/front_bodice.ron"][which]);
        let text = mutate(&base, &edits);
        let t = text.clone();
        guarded("the pattern loader and gridder", &text, move || load_pattern(t));
    }

    #[test]
    fn dxf_pattern_files(edits in prop::collection::vec(edit(), 1..6), which in 0usize..3) {
        let base = fixture(["fixtures/patterns/dxf/bad/unknown_entities.dxf",
            "fixtures/patterns/dxf/bad/two_pieces_same_name.dxf",
            "fixtures/patterns/dxf/bad/open_outline.dxf"][which]);
        let text = mutate(&base, &edits);
        let t = text.clone();
        guarded("the DXF pattern reader and gridder", &text, move || load_dxf_pattern(t));
    }

    #[test]
    fn svg_pattern_files(edits in prop::collection::vec(edit(), 1..6)) {
        let text = mutate(SVG, &edits);
        let t = text.clone();
        guarded("the SVG pattern reader and gridder", &text, move || load_svg_pattern(t));
    }

    #[test]
    fn garment_files(edits in prop::collection::vec(edit(), 1..6)) {
        let text = mutate(&fixture("fixtures/patterns/dress/skirt.ron"), &edits);
        let t = text.clone();
        guarded("the garment loader", &text, move || load_garment(t));
    }

    #[test]
    fn body_files(edits in prop::collection::vec(edit(), 1..6)) {
        let text = mutate(&fixture("fixtures/bodies/jis_9ar.ron"), &edits);
        let t = text.clone();
        guarded("the body loader and builder", &text, move || load_body(t));
    }

    #[test]
    fn motion_files(edits in prop::collection::vec(edit(), 1..6), which in 0usize..2) {
        let base = fixture(["fixtures/motions/walk.ron", "fixtures/motions/arm_raise.ron"][which]);
        let text = mutate(&base, &edits);
        let t = text.clone();
        guarded("the motion loader", &text, move || load_motion(t, mannequin()));
    }

    #[test]
    fn observation_files(edits in prop::collection::vec(edit(), 1..6)) {
        let text = mutate(observations_fixture(), &edits);
        let t = text.clone();
        guarded("the observation loader", &text, move || load_observations(t));
    }

    #[test]
    fn scenario_files(edits in prop::collection::vec(edit(), 1..6), which in 0usize..4) {
        let base = fixture(["fixtures/scenarios/dress_walk.ron", "fixtures/scenarios/drape_jis_silk.ron",
            "fixtures/scenarios/wet_pinch1_air400.ron", "fixtures/scenarios/fit_cable_j4.ron"][which]);
        let text = mutate(&base, &edits);
        let t = text.clone();
        guarded("the scenario loader", &text, move || load_scenario(t));
    }

    #[test]
    fn mesh_files(edits in prop::collection::vec(edit(), 1..6), ply in any::<bool>()) {
        let text = mutate(if ply { PLY } else { OBJ }, &edits);
        let t = text.clone();
        guarded("the mesh loaders", &text, move || load_mesh(t));
    }

    #[test]
    fn cloth_observation_files(edits in prop::collection::vec(edit(), 1..6)) {
        let text = mutate(CLOTH, &edits);
        let t = text.clone();
        guarded("atelier fit", &text, move || load_cloth_observations(t));
    }

    #[test]
    fn tryon_pose_files(edits in prop::collection::vec(edit(), 1..6)) {
        let base = "(camera: (yaw_deg: 30.0, scale: 240.0, origin_px: (210.0, 435.0)), sizes: (height_cm: 158.0, bust_cm: 88.0, waist_cm: 67.9, hip_cm: 96.5), joints: {\"upper_arm_left\": (-10.0, 0.0, 75.0), \"forearm_left\": (-20.0, 0.0, 0.0)})";
        let text = mutate(base, &edits);
        let t = text.clone();
        guarded("the try-on pose loader", &text, move || load_pose(t));
    }

    #[test]
    fn tryon_pictures(flips in prop::collection::vec((any::<usize>(), any::<u8>()), 1..8), cut in any::<usize>(), which in 0usize..2) {
        let name = ["fixtures/tryon/arms_raised_mask.png", "fixtures/tryon/mid_stride.png"][which];
        let mut bytes = std::fs::read(root().join(name)).expect("fixture");
        for (p, b) in flips {
            let i = p % bytes.len();
            bytes[i] = b;
        }
        if cut % 3 == 0 {
            bytes.truncate(cut % (bytes.len() + 1));
        }
        guarded("the try-on picture loaders", name, move || load_picture(bytes));
    }

    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..2048)) {
        let text = String::from_utf8_lossy(&bytes).into_owned();
        for (what, load) in [
            ("fabric", Box::new(load_fabric) as Box<dyn FnOnce(String) + Send>),
            ("pattern", Box::new(load_pattern)),
            ("garment", Box::new(load_garment)),
            ("body", Box::new(load_body)),
            ("motion", Box::new(|t| load_motion(t, mannequin()))),
            ("observations", Box::new(load_observations)),
            ("scenario", Box::new(load_scenario)),
            ("mesh", Box::new(load_mesh)),
            ("DXF pattern", Box::new(load_dxf_pattern)),
            ("SVG pattern", Box::new(load_svg_pattern)),
            ("cloth observations", Box::new(load_cloth_observations)),
        ] {
            let t = text.clone();
            guarded(what, &text, move || load(t));
        }
    }
}
