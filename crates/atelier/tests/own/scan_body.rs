//! A body scan as a garment scene's body (issue 24): the MakeHuman base mesh (CC0, not atelier's
//! mannequin) read, repaired, landmarked, segmented and articulated by the scene loader; a
//! declared unit that makes it absurdly sized refused with its height; `body` and `body_scan`
//! together refused. The sewn scenes on the scan are `fixtures/scenarios/*_on_scan.ron`.

use std::path::PathBuf;

use atelier::scenario::{Scenario, ScenarioKind};
use atelier::{BodyScanSpec, GarmentSpec, LengthUnit, Scene, SceneError};

fn scenarios() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios")
}

fn skirt_on_scan() -> GarmentSpec {
    let s = Scenario::load(&scenarios().join("skirt_on_scan.ron")).expect("scenario");
    let ScenarioKind::Garment(spec) = s.kind else {
        panic!("a garment scenario")
    };
    spec
}

#[test]
fn a_scan_becomes_the_scene_body_with_its_own_surface() {
    let spec = skirt_on_scan();
    let scene = Scene::load(&spec, &scenarios()).unwrap_or_else(|e| panic!("{e}"));
    // Every triangle of the scan is in the body (the parts add only the caps of their cuts:
    // a fan of one vertex per cut border).
    let (vertices, triangles) = scene.body.mannequin.counts();
    assert!(
        triangles > 26_756 && vertices > 13_380,
        "{vertices} vertices, {triangles} triangles"
    );
    // The MakeHuman README's rest height, 166.589 cm: the body is the scan, in metres.
    let top = scene
        .body
        .mannequin
        .parts
        .iter()
        .flat_map(|p| p.vertices.iter())
        .map(|v| v.y)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!((top - 1.66589).abs() < 1e-5, "top of the head at {top} m");
    assert!(
        scene.notes.iter().any(|n| n.contains("waist")),
        "the landmarks are reported: {:?}",
        scene.notes
    );
}

#[test]
fn a_wrong_unit_or_two_bodies_are_refused() {
    let mut spec = skirt_on_scan();
    let mesh = spec.body.take().expect("the scenario names the scan");
    spec.body_scan = Some(BodyScanSpec {
        mesh: mesh.clone(),
        unit: LengthUnit::Mm,
        landmarks: None,
    });
    let e = Scene::load(&spec, &scenarios())
        .err()
        .expect("a 1.7 mm body");
    assert!(
        matches!(e, SceneError::Scan { .. }) && e.to_string().contains("0.001666 m"),
        "{e}"
    );
    spec.body = Some(mesh);
    let e = Scene::load(&spec, &scenarios()).err().expect("two bodies");
    assert!(matches!(e, SceneError::TwoBodies), "{e}");
}
