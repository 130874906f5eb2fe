//! Articulating a body brought from outside (a scan in OBJ or PLY with a part label on every
//! vertex and triangle): split it into the 17 rigid parts, estimate each joint's pivot where a
//! part meets its parent, and take the joint limits from a reference mannequin — then it poses
//! and moves like the parametric mannequin.

use crate::model::{LabelledMesh, Mannequin, Part, PartMesh, V3};

/// Why a labelled mesh cannot be articulated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ArticulateError {
    /// Label arrays of the wrong length.
    #[error("{what} labels: {found} for {expected} items")]
    LabelCount {
        /// `vertex` or `triangle`.
        what: &'static str,
        /// Labels given.
        found: usize,
        /// Items.
        expected: usize,
    },
    /// A part has no triangles.
    #[error("part `{}` has no triangles in the mesh", .0.name())]
    MissingPart(Part),
}

/// Split `mesh` into its parts and estimate the pivots: a joint's pivot is the centroid of the
/// child's vertices that lie inside the parent's mesh or within `reach` (m) of its vertices
/// (where the two parts meet), or, where none do, the child's vertex nearest to the parent. The pelvis keeps the
/// reference's pivot height, at the centroid of the pelvis vertices in x and z. Joint limits come
/// from `limits_from` (same joints).
pub fn articulate(
    mesh: &LabelledMesh,
    limits_from: &Mannequin,
    reach: f64,
) -> Result<Mannequin, ArticulateError> {
    if mesh.vertex_part.len() != mesh.vertices.len() {
        return Err(ArticulateError::LabelCount {
            what: "vertex",
            found: mesh.vertex_part.len(),
            expected: mesh.vertices.len(),
        });
    }
    if mesh.triangle_part.len() != mesh.triangles.len() {
        return Err(ArticulateError::LabelCount {
            what: "triangle",
            found: mesh.triangle_part.len(),
            expected: mesh.triangles.len(),
        });
    }
    // Each part's triangles with its own vertex numbering.
    let mut parts: Vec<(Vec<V3>, Vec<[u32; 3]>)> = vec![(Vec::new(), Vec::new()); 17];
    let mut local = vec![[u32::MAX; 17]; 0];
    local.resize(mesh.vertices.len(), [u32::MAX; 17]);
    for (t, &p) in mesh.triangles.iter().zip(&mesh.triangle_part) {
        let k = p.index();
        let tri = t.map(|v| {
            let slot = &mut local[v as usize][k];
            if *slot == u32::MAX {
                *slot = parts[k].0.len() as u32;
                parts[k].0.push(mesh.vertices[v as usize]);
            }
            *slot
        });
        parts[k].1.push(tri);
    }
    if let Some(p) = Part::ALL
        .into_iter()
        .find(|p| parts[p.index()].1.is_empty())
    {
        return Err(ArticulateError::MissingPart(p));
    }
    let centroid = |v: &[V3]| v.iter().sum::<V3>() / v.len() as f64;
    let pivots: Vec<V3> = Part::ALL
        .iter()
        .map(|&p| match p.parent() {
            None => {
                let c = centroid(&parts[p.index()].0);
                V3::new(c.x, limits_from.part(p).pivot.y, c.z)
            }
            Some(parent) => {
                let (child, par) = (&parts[p.index()].0, &parts[parent.index()].0);
                let par_tris = &parts[parent.index()].1;
                // Where the parts meet: the child's vertices inside the parent (parts that
                // overlap, like the parametric mannequin's) or within `reach` of it (a scan cut
                // into touching parts).
                let near: Vec<V3> = child
                    .iter()
                    .filter(|v| {
                        par.iter().any(|q| (*v - q).norm() <= reach)
                            || crate::build::contains(par, par_tris, v)
                    })
                    .copied()
                    .collect();
                if near.is_empty() {
                    let pc = centroid(par);
                    *child
                        .iter()
                        .min_by(|a, b| (*a - pc).norm().total_cmp(&(*b - pc).norm()))
                        .expect("non-empty part")
                } else {
                    centroid(&near)
                }
            }
        })
        .collect();
    let parts = Part::ALL
        .iter()
        .zip(parts)
        .zip(pivots)
        .map(|((&part, (vertices, triangles)), pivot)| PartMesh {
            part,
            vertices,
            triangles,
            pivot,
            limits: limits_from.part(part).limits,
        })
        .collect();
    Ok(Mannequin {
        name: "articulated external body".into(),
        parts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{ExternalBody, load_mesh, write_obj};
    use crate::kinematics::Body;
    use crate::motion::Motion;

    #[test]
    fn a_labelled_scan_is_articulated_and_walks() {
        // The parametric mannequin written to OBJ with part groups stands in for a labelled scan.
        let reference = crate::build::jis_9ar();
        let mesh = reference.labelled_mesh();
        let dir = std::env::temp_dir().join(format!("atelier-articulate-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("scan.obj");
        write_obj(&path, &ExternalBody::from(&mesh)).expect("write");
        let scan = load_mesh(&path)
            .expect("load")
            .labelled()
            .expect("labelled");
        let m = articulate(&scan, &reference, 0.01).expect("articulates");
        // Each estimated pivot lies within a few centimetres of the mannequin's own joint, and
        // inside the parent part or the child (where the parts meet).
        let mut worst = 0.0f64;
        for (a, b) in m.parts.iter().zip(&reference.parts) {
            let d = (a.pivot - b.pivot).norm();
            worst = worst.max(d);
            assert!(d < 0.05, "{:?}: pivot {d:.3} m from the reference", a.part);
        }
        eprintln!("largest pivot error {worst:.3} m");
        // It walks: rigid parts, finite, the legs swing.
        let walk = Motion::load(
            &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../fixtures/motions/walk.ron"),
            &m,
        )
        .expect("walk");
        let body = Body::new(m);
        let posed = body.at(&walk, 2.5);
        assert!(
            posed
                .positions
                .iter()
                .all(|p| p.iter().all(|c| c.is_finite()))
        );
        assert!(body.max_displacement(&walk, 2.5, 0.01) > 0.005);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_mesh_without_a_part_is_refused() {
        let reference = crate::build::jis_9ar();
        let mut mesh = reference.labelled_mesh();
        for p in &mut mesh.triangle_part {
            if *p == Part::HandLeft {
                *p = Part::ForearmLeft;
            }
        }
        assert_eq!(
            articulate(&mesh, &reference, 0.01).unwrap_err(),
            ArticulateError::MissingPart(Part::HandLeft)
        );
        mesh.vertex_part.pop();
        assert!(matches!(
            articulate(&mesh, &reference, 0.01),
            Err(ArticulateError::LabelCount { what: "vertex", .. })
        ));
    }
}
