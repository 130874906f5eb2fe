//! The final meshes as Wavefront OBJ and as binary PLY with vertex colours.

use std::io::Write;
use std::path::Path;

use super::{
    ExportError, MeshPart, check_static, colour_bytes, invalid_scene, one_line_name, put_f32s,
    to_f32, vertex_normals, write_atomically,
};

/// Write the parts' meshes (each with its own positions, m) as a Wavefront OBJ file: a comment
/// header, then per part an `o` group with its vertices (`v`, full double precision),
/// area-weighted unit vertex normals (`vn`) and triangles (`f v//vn`, 1-based, numbered across
/// the whole file). Colours and sidedness are not stored (OBJ has no standard for them).
pub fn write_obj(path: &Path, parts: &[(MeshPart<'_>, &[[f64; 3]])]) -> Result<(), ExportError> {
    check_static(path, parts)?;
    let vertices: usize = parts.iter().map(|(_, p)| p.len()).sum();
    let triangles: usize = parts.iter().map(|(m, _)| m.triangles.len()).sum();
    write_atomically(path, |w| {
        writeln!(
            w,
            "# atelier export: {} parts, {vertices} vertices, {triangles} triangles",
            parts.len()
        )?;
        writeln!(w, "# metres; x = the body's left, y up, z forward")?;
        let mut offset = 1usize;
        for (part, positions) in parts {
            writeln!(w, "o {}", one_line_name(part.name))?;
            for p in *positions {
                writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
            }
            for n in vertex_normals(positions, part.triangles) {
                let n = to_f32(n);
                writeln!(w, "vn {} {} {}", n[0], n[1], n[2])?;
            }
            for tri in part.triangles {
                let [a, b, c] = tri.map(|i| i as usize + offset);
                writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
            }
            offset += positions.len();
        }
        Ok(())
    })
}

/// Write the parts' meshes as a binary little-endian PLY file: one vertex element (`x y z` and
/// `nx ny nz` as `float`, area-weighted unit normals; `red green blue` as `uchar`, the part's
/// colour) and one face element (`list uchar int vertex_indices`), parts one after the other;
/// a header comment per part gives its name and its vertex and face ranges.
pub fn write_ply(path: &Path, parts: &[(MeshPart<'_>, &[[f64; 3]])]) -> Result<(), ExportError> {
    check_static(path, parts)?;
    let vertices: usize = parts.iter().map(|(_, p)| p.len()).sum();
    let faces: usize = parts.iter().map(|(m, _)| m.triangles.len()).sum();
    if vertices > i32::MAX as usize {
        return Err(invalid_scene(
            path,
            format!("{vertices} vertices exceed PLY's int indices"),
        ));
    }
    let mut header = String::from("ply\nformat binary_little_endian 1.0\n");
    header.push_str("comment atelier export: metres; x = the body's left, y up, z forward\n");
    let (mut v0, mut f0) = (0usize, 0usize);
    for (part, positions) in parts {
        let (v1, f1) = (v0 + positions.len(), f0 + part.triangles.len());
        header.push_str(&format!(
            "comment part {}: vertices {v0}..{v1}, faces {f0}..{f1}\n",
            one_line_name(part.name)
        ));
        (v0, f0) = (v1, f1);
    }
    header.push_str(&format!("element vertex {vertices}\n"));
    for p in ["x", "y", "z", "nx", "ny", "nz"] {
        header.push_str(&format!("property float {p}\n"));
    }
    for p in ["red", "green", "blue"] {
        header.push_str(&format!("property uchar {p}\n"));
    }
    header.push_str(&format!(
        "element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    ));
    write_atomically(path, |w| {
        w.write_all(header.as_bytes())?;
        for (part, positions) in parts {
            let rgb = colour_bytes(part.colour);
            for (p, n) in positions
                .iter()
                .zip(vertex_normals(positions, part.triangles))
            {
                put_f32s(w, to_f32(*p))?;
                put_f32s(w, to_f32(n))?;
                w.write_all(&rgb)?;
            }
        }
        let mut offset = 0i32;
        for (part, positions) in parts {
            for tri in part.triangles {
                w.write_all(&[3])?;
                for &i in tri {
                    w.write_all(&(i as i32 + offset).to_le_bytes())?;
                }
            }
            offset += positions.len() as i32;
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// glTF binary.
