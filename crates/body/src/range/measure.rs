//! The error of a gridded body as the thesis measures it (§4.7.2, Fig. 36, Table 2): render range
//! images `Z_e` of the mesh at the measured pixels (orthographic z-buffer, front = largest z,
//! back = smallest z), compare with the measured `Z_r` on the samples valid in both, per part
//! (the part of the triangle seen at the sample) and in total.

use super::body::RangeBody;
use super::gridding::BodyMesh;
use crate::part::Part;

/// Error statistics of one part or of the whole body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    /// Samples compared (front and back).
    pub samples: usize,
    /// Mean of `|Z_e − Z_r|`, mm.
    pub mean_abs_mm: f64,
    /// Standard deviation of `|Z_e − Z_r|`, mm.
    pub sd_abs_mm: f64,
    /// Mean of the signed difference `Z_e − Z_r` measured outwards (front `Z_e − Z_r`, back
    /// `Z_r − Z_e`: positive when the mesh lies outside the measured surface), mm.
    pub mean_signed_mm: f64,
    /// Standard deviation of the signed difference, mm.
    pub sd_signed_mm: f64,
    /// Mesh vertices labelled with this part (all vertices for the total).
    pub nodes: usize,
    /// Mesh triangles labelled with this part.
    pub triangles: usize,
}

/// A rendered view: per sample the mesh depth, the difference and the part seen.
///
/// Samples are stored like [`RangeBody`]'s, in the front image's column order (column `c` at
/// world `x = origin_x + c·pixel`) for both views.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorImage {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `Z_e`, mm (NaN where the mesh does not cover the sample).
    pub rendered_mm: Vec<f32>,
    /// Outward difference (see [`ErrorStats::mean_signed_mm`]), mm; NaN where not compared.
    pub error_mm: Vec<f32>,
    /// Part index of the triangle seen ([`Part::index`]), 255 where none.
    pub part: Vec<u8>,
}

/// The error report (Table 2 of the thesis).
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorReport {
    /// Per part, in [`Part::ALL`] order.
    pub parts: Vec<(Part, ErrorStats)>,
    /// All parts together.
    pub total: ErrorStats,
    /// Valid samples of the two range images (the "effective data").
    pub valid_samples: usize,
    /// Vertices / valid samples.
    pub compression: f64,
    /// Valid samples the mesh does not cover.
    pub uncovered: usize,
    /// Samples the mesh covers where the range image has none.
    pub spurious: usize,
    /// The front view.
    pub front: ErrorImage,
    /// The back view.
    pub back: ErrorImage,
}

impl ErrorReport {
    /// The per-part table of the thesis's Table 2 (nodes, triangles, samples, |Z_e − Z_r| and
    /// the signed error, mm) with a total row, as text.
    pub fn table(&self) -> String {
        let row = |name: &str, s: &ErrorStats| {
            format!(
                "{name:<16} {:6} {:5} {:8}  {:5.2} ± {:5.2}  {:6.2} ± {:5.2}\n",
                s.nodes,
                s.triangles,
                s.samples,
                s.mean_abs_mm,
                s.sd_abs_mm,
                s.mean_signed_mm,
                s.sd_signed_mm
            )
        };
        let mut out =
            String::from("part              nodes  tris  samples  |Ze−Zr| mm      signed mm\n");
        for (p, s) in &self.parts {
            out.push_str(&row(p.name(), s));
        }
        out.push_str(&row("total", &self.total));
        out
    }
}

fn render(mesh: &BodyMesh, body: &RangeBody, front: bool) -> (Vec<f64>, Vec<u8>) {
    let (w, h) = (body.width, body.height);
    let mut z = vec![f64::NAN; w * h];
    let mut part = vec![255u8; w * h];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let p = tri.map(|i| {
            let q = mesh.positions[i as usize];
            let c = body.pixel([q[0] * 1e3, q[1] * 1e3]);
            [c[0], c[1], q[2] * 1e3]
        });
        let label = mesh.triangle_part[t].index() as u8;
        rasterize_triangle(p, label, front, w, h, &mut z, &mut part);
    }
    (z, part)
}

/// Rasterise one triangle given in pixel coordinates (column, row) with its depth (mm, world
/// z): at every pixel centre inside it (inclusive, 1e-9 tolerance on the barycentric
/// coordinates) keep the depth nearest the camera — the largest z for the front view, the
/// smallest for the back — and `label`. `z` (NaN = empty) and `part` are `w × h`, row by row.
/// Shared by this error measure and by the range-image renderer of `atelier-body`, so both see
/// exactly the same pixels.
pub fn rasterize_triangle(
    p: [[f64; 3]; 3],
    label: u8,
    front: bool,
    w: usize,
    h: usize,
    z: &mut [f64],
    part: &mut [u8],
) {
    let det = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    if det.abs() < 1e-12 || w == 0 || h == 0 {
        return;
    }
    let (mut c0, mut c1, mut r0, mut r1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for q in &p {
        c0 = c0.min(q[0]);
        c1 = c1.max(q[0]);
        r0 = r0.min(q[1]);
        r1 = r1.max(q[1]);
    }
    let (c0, c1) = (
        (c0 - 1e-9).ceil().max(0.0),
        (c1 + 1e-9).floor().min((w - 1) as f64),
    );
    let (r0, r1) = (
        (r0 - 1e-9).ceil().max(0.0),
        (r1 + 1e-9).floor().min((h - 1) as f64),
    );
    if c0 > c1 || r0 > r1 {
        return;
    }
    for r in r0 as usize..=r1 as usize {
        let y = r as f64;
        for c in c0 as usize..=c1 as usize {
            let x = c as f64;
            let l1 =
                ((x - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (y - p[0][1])) / det;
            let l2 =
                ((p[1][0] - p[0][0]) * (y - p[0][1]) - (x - p[0][0]) * (p[1][1] - p[0][1])) / det;
            let l0 = 1.0 - l1 - l2;
            let eps = -1e-9;
            if l0 < eps || l1 < eps || l2 < eps {
                continue;
            }
            let zz = l0 * p[0][2] + l1 * p[1][2] + l2 * p[2][2];
            let k = r * w + c;
            let better = z[k].is_nan() || if front { zz > z[k] } else { zz < z[k] };
            if better {
                z[k] = zz;
                part[k] = label;
            }
        }
    }
}

#[derive(Default, Clone, Copy)]
struct Acc {
    n: usize,
    sa: f64,
    sa2: f64,
    ss: f64,
    ss2: f64,
}

impl Acc {
    fn add(&mut self, d: f64) {
        self.n += 1;
        self.sa += d.abs();
        self.sa2 += d * d;
        self.ss += d;
        self.ss2 += d * d;
    }
    fn stats(&self, nodes: usize, triangles: usize) -> ErrorStats {
        let n = self.n.max(1) as f64;
        let (ma, ms) = (self.sa / n, self.ss / n);
        ErrorStats {
            samples: self.n,
            mean_abs_mm: ma,
            sd_abs_mm: (self.sa2 / n - ma * ma).max(0.0).sqrt(),
            mean_signed_mm: ms,
            sd_signed_mm: (self.ss2 / n - ms * ms).max(0.0).sqrt(),
            nodes,
            triangles,
        }
    }
}

/// Measure the mesh against the body's range images.
pub fn measure_error(mesh: &BodyMesh, body: &RangeBody) -> ErrorReport {
    let mut acc = [Acc::default(); 17];
    let mut total = Acc::default();
    let (mut uncovered, mut spurious) = (0, 0);
    let mut images = Vec::new();
    for front in [true, false] {
        let (ze, part) = render(mesh, body, front);
        let zr = if front { &body.front } else { &body.back };
        let mut error = vec![f32::NAN; ze.len()];
        for k in 0..ze.len() {
            match (ze[k].is_nan(), zr[k].is_nan()) {
                (false, false) => {
                    let d = if front { ze[k] - zr[k] } else { zr[k] - ze[k] };
                    error[k] = d as f32;
                    acc[part[k] as usize].add(d);
                    total.add(d);
                }
                (true, false) => uncovered += 1,
                (false, true) => spurious += 1,
                (true, true) => {}
            }
        }
        images.push(ErrorImage {
            width: body.width,
            height: body.height,
            rendered_mm: ze.iter().map(|&v| v as f32).collect(),
            error_mm: error,
            part,
        });
    }
    let nv = mesh.part_vertex_counts();
    let nt = mesh.part_triangle_counts();
    let valid = body.valid_samples();
    let back = images.pop().unwrap_or_else(|| unreachable!());
    let front = images.pop().unwrap_or_else(|| unreachable!());
    ErrorReport {
        parts: Part::ALL
            .iter()
            .map(|&p| (p, acc[p.index()].stats(nv[p.index()], nt[p.index()])))
            .collect(),
        total: total.stats(mesh.positions.len(), mesh.triangles.len()),
        valid_samples: valid,
        compression: mesh.positions.len() as f64 / valid.max(1) as f64,
        uncovered,
        spurious,
        front,
        back,
    }
}
