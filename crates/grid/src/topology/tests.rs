//! Tests of [`super`].

use super::*;
use approx::assert_relative_eq;

#[test]
fn sheet_counts_areas_and_angles() {
    let t = ClothTopology::from_structured(&StructuredGrid::sheet(4, 3, 0.3, 0.2)).expect("valid");
    assert_eq!(t.node_count(), 12);
    // Axial: 3·3 along u + 4·2 along v; diagonals: 2 per cell, 3·2 cells.
    assert_eq!(t.edges().len(), 9 + 8 + 12);
    assert_eq!(t.triangles().len(), 12);
    assert_relative_eq!(t.area(), 0.06, max_relative = 1e-12);
    // Interior node area h_u·h_v = 0.1·0.1, corner a quarter of it.
    assert_relative_eq!(t.node_areas()[5], 0.01, max_relative = 1e-12);
    assert_relative_eq!(t.node_areas()[0], 0.0025, max_relative = 1e-12);
    for e in t.edges() {
        let expect = match e.kind {
            EdgeKind::AxialV => 0.0,
            EdgeKind::AxialU => PI / 2.0,
            EdgeKind::Diagonal => {
                assert!(
                    (e.material_angle - PI / 4.0).abs() < 1e-12
                        || (e.material_angle - 3.0 * PI / 4.0).abs() < 1e-12
                );
                continue;
            }
        };
        assert_relative_eq!(e.material_angle, expect, epsilon = 1e-12);
    }
    assert_counter_clockwise(&t);
}

/// Every triangle has positive signed area in the pattern plane.
fn assert_counter_clockwise(t: &ClothTopology) {
    for tri in t.triangles() {
        let p = tri.map(|k| t.rest_positions()[k as usize]);
        let area =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        assert!(area > 0.0, "triangle {tri:?} has area {area}");
    }
}

#[test]
fn annulus_wraps_and_keeps_orientation() {
    let t = ClothTopology::from_structured(&StructuredGrid::annulus(60, 6, 0.0635, 0.3175))
        .expect("valid");
    assert_eq!(t.node_count(), 360);
    // Every node has both u neighbours.
    assert!(
        t.axial_neighbours()
            .iter()
            .all(|s| s[0] != NO_NODE && s[1] != NO_NODE)
    );
    let exact = PI * (0.3175f64.powi(2) - 0.0635f64.powi(2));
    // Polygonal rings: area within 0.2 % of the circle annulus for 60 sectors.
    assert_relative_eq!(t.area(), exact, max_relative = 2e-3);
    assert_counter_clockwise(&t);
}

#[test]
fn colours_share_no_node_and_incidence_is_complete() {
    let t = ClothTopology::from_structured(&StructuredGrid::sheet(7, 5, 0.6, 0.4)).expect("valid");
    let colours = t.edge_colours();
    let mut seen = 0;
    for c in &colours {
        let mut nodes = std::collections::HashSet::new();
        for &e in c {
            let e = t.edges()[e as usize];
            assert!(nodes.insert(e.a) && nodes.insert(e.b));
        }
        seen += c.len();
    }
    assert_eq!(seen, t.edges().len());
    assert!(colours.len() <= 10, "{} colours", colours.len());
    let total: usize = (0..t.node_count()).map(|i| t.incident_edges(i).len()).sum();
    assert_eq!(total, 2 * t.edges().len());
    let total: usize = (0..t.node_count())
        .map(|i| t.incident_triangles(i).len())
        .sum();
    assert_eq!(total, 3 * t.triangles().len());
    // Every diagonal borders one cell, every interior axial edge two.
    for (e, cells) in t.edges().iter().zip(t.edge_cells()) {
        let count = cells.iter().filter(|&&c| c != NO_NODE).count();
        match e.kind {
            EdgeKind::Diagonal => assert_eq!(count, 1),
            _ => assert!(count == 1 || count == 2),
        }
    }
    for c in t.cells() {
        assert!((c.rest_angle - PI / 2.0).abs() < 1e-12);
        assert!((c.area - 0.01).abs() < 1e-12);
        let d = t.edges()[c.diagonals[0] as usize];
        assert_eq!([d.a, d.b], [c.nodes[0], c.nodes[2]]);
    }
    assert_eq!(t.incident_edges(8 + 7).len(), 8);
}

#[test]
fn a_union_keeps_every_part_intact() {
    let a = ClothTopology::from_structured(&StructuredGrid::sheet(4, 3, 0.3, 0.2)).expect("a");
    let b = ClothTopology::from_structured(&StructuredGrid::annulus(12, 3, 0.1, 0.2)).expect("b");
    let (u, offsets) = ClothTopology::union(&[&a, &b]);
    assert_eq!(offsets, vec![0, 12]);
    assert_eq!(u.node_count(), a.node_count() + b.node_count());
    assert_eq!(u.edges().len(), a.edges().len() + b.edges().len());
    assert_eq!(u.cells().len(), a.cells().len() + b.cells().len());
    assert_relative_eq!(u.area(), a.area() + b.area(), max_relative = 1e-15);
    // Part b's structure, shifted.
    let (n0, e0) = (12u32, a.edges().len() as u32);
    for (eu, eb) in u.edges()[e0 as usize..].iter().zip(b.edges()) {
        assert_eq!((eu.a, eu.b), (eb.a + n0, eb.b + n0));
        assert!((eu.rest_length - eb.rest_length).abs() < 1e-15);
    }
    for (k, s) in b.axial_neighbours().iter().enumerate() {
        let su = u.axial_neighbours()[k + 12];
        for j in 0..SLOTS {
            assert_eq!(su[j], if s[j] == NO_NODE { NO_NODE } else { s[j] + n0 });
        }
    }
    let total: usize = (0..u.node_count()).map(|i| u.incident_edges(i).len()).sum();
    assert_eq!(total, 2 * u.edges().len());
    assert_counter_clockwise(&u);
}

#[test]
fn bad_grids_are_rejected() {
    let mut g = StructuredGrid::sheet(3, 3, 1.0, 1.0);
    g.positions[4] = [f64::NAN, 0.0];
    assert!(matches!(
        ClothTopology::from_structured(&g),
        Err(TopologyError::NotFinite { node: 4, .. })
    ));
    let mut g = StructuredGrid::sheet(3, 3, 1.0, 1.0);
    g.positions[4] = [3.0, 3.0];
    assert!(matches!(
        ClothTopology::from_structured(&g),
        Err(TopologyError::BadCell { .. })
    ));
    assert!(matches!(
        ClothTopology::from_structured(&StructuredGrid::sheet(1, 3, 1.0, 1.0)),
        Err(TopologyError::TooSmall { .. })
    ));
}
