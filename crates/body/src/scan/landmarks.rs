//! Landmarks of a standing body found on its surface: horizontal sections for the trunk
//! (crotch, armpits, hip, waist, bust, neck) and rings along the limbs (geodesic distance from
//! where the limb leaves the trunk) for the joints of the arms and legs. The rules are stated on
//! [`Landmarks`]'s fields and in docs/body.md ("Scans").

use std::path::Path;

use atelier_files::FileError;
use serde::Deserialize;

use super::limbs::{Adjacency, ArmMarks, LegMarks, Limb, arm_marks, leg_marks};
use super::slice::{Contour, Field, bbox_xz, boxes_overlap, hull_perimeter_xz, overlap_xz};
use super::{ScanError, ScanOptions};
use crate::model::V3;

/// A girth line: its height, the tape-measure girth there and the section's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Girth {
    /// Height of the line, m.
    pub height: f64,
    /// Perimeter of the convex hull of the trunk's horizontal section, m (a tape laid round the
    /// body bridges the hollows).
    pub girth: f64,
    /// Centroid of the section's outline, m.
    pub centre: V3,
}

/// The landmarks of a scan, body frame, metres. Joint centres (shoulders, elbows, wrists, hips,
/// knees, ankles, neck base, head base) lie inside the body; the crotch and armpits are where
/// the surface parts.
#[derive(Clone, Debug, PartialEq)]
pub struct Landmarks {
    /// Top of the gap between the legs: the highest section where the legs are apart.
    pub crotch: V3,
    /// Left armpit: the highest section where the left arm is apart from the trunk.
    pub armpit_left: V3,
    /// Right armpit.
    pub armpit_right: V3,
    /// Hip line: the largest trunk girth between the crotch and the waist.
    pub hip: Girth,
    /// Waist: the smallest trunk girth in the middle of the trunk (35–85 % of the way from the
    /// crotch to the lower armpit).
    pub waist: Girth,
    /// Bust: the largest trunk girth between the waist and the lower armpit.
    pub bust: Girth,
    /// Neck: the smallest girth of the central section between the higher armpit and 10 % of
    /// the height below the crown.
    pub neck: Girth,
    /// Base of the neck (the chest–neck joint): the centre of the lowest section above the
    /// armpits whose girth is within 20 % of the neck's.
    pub neck_base: V3,
    /// Chin: the front of the first section above the neck whose girth exceeds the neck's by
    /// 20 % (the jaw); the neck–head cut passes through it.
    pub chin: V3,
    /// Left shoulder joint.
    pub shoulder_left: V3,
    /// Right shoulder joint.
    pub shoulder_right: V3,
    /// Left elbow.
    pub elbow_left: V3,
    /// Right elbow.
    pub elbow_right: V3,
    /// Left wrist.
    pub wrist_left: V3,
    /// Right wrist.
    pub wrist_right: V3,
    /// Tip of the left hand (the point farthest along the arm).
    pub hand_tip_left: V3,
    /// Tip of the right hand.
    pub hand_tip_right: V3,
    /// Left hip joint.
    pub hip_left: V3,
    /// Right hip joint.
    pub hip_right: V3,
    /// Left knee.
    pub knee_left: V3,
    /// Right knee.
    pub knee_right: V3,
    /// Left ankle.
    pub ankle_left: V3,
    /// Right ankle.
    pub ankle_right: V3,
    /// Tip of the left foot (the point farthest along the leg).
    pub toe_left: V3,
    /// Tip of the right foot.
    pub toe_right: V3,
    /// Height (highest − lowest y), m.
    pub height: f64,
}

/// Landmarks given by hand: a RON file whose fields (all optional, metres, body frame) replace
/// the found ones. Points are `(x, y, z)`; girth lines are heights (the girth is measured again
/// at the given height only by [`super::prepare`]'s caller if wanted; the found girth is kept).
///
/// ```ron
/// (knee_left: (0.16, 0.45, -0.04), waist_height: 1.02)
/// ```
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandmarkFile {
    /// Where the landmarks come from (free text).
    #[serde(default)]
    pub provenance: Option<String>,
    /// [`Landmarks::crotch`].
    #[serde(default)]
    pub crotch: Option<(f64, f64, f64)>,
    /// [`Landmarks::armpit_left`].
    #[serde(default)]
    pub armpit_left: Option<(f64, f64, f64)>,
    /// [`Landmarks::armpit_right`].
    #[serde(default)]
    pub armpit_right: Option<(f64, f64, f64)>,
    /// Height of [`Landmarks::hip`].
    #[serde(default)]
    pub hip_height: Option<f64>,
    /// Height of [`Landmarks::waist`].
    #[serde(default)]
    pub waist_height: Option<f64>,
    /// Height of [`Landmarks::bust`].
    #[serde(default)]
    pub bust_height: Option<f64>,
    /// Height of [`Landmarks::neck`].
    #[serde(default)]
    pub neck_height: Option<f64>,
    /// [`Landmarks::neck_base`].
    #[serde(default)]
    pub neck_base: Option<(f64, f64, f64)>,
    /// [`Landmarks::chin`].
    #[serde(default)]
    pub chin: Option<(f64, f64, f64)>,
    /// [`Landmarks::shoulder_left`].
    #[serde(default)]
    pub shoulder_left: Option<(f64, f64, f64)>,
    /// [`Landmarks::shoulder_right`].
    #[serde(default)]
    pub shoulder_right: Option<(f64, f64, f64)>,
    /// [`Landmarks::elbow_left`].
    #[serde(default)]
    pub elbow_left: Option<(f64, f64, f64)>,
    /// [`Landmarks::elbow_right`].
    #[serde(default)]
    pub elbow_right: Option<(f64, f64, f64)>,
    /// [`Landmarks::wrist_left`].
    #[serde(default)]
    pub wrist_left: Option<(f64, f64, f64)>,
    /// [`Landmarks::wrist_right`].
    #[serde(default)]
    pub wrist_right: Option<(f64, f64, f64)>,
    /// [`Landmarks::hip_left`].
    #[serde(default)]
    pub hip_left: Option<(f64, f64, f64)>,
    /// [`Landmarks::hip_right`].
    #[serde(default)]
    pub hip_right: Option<(f64, f64, f64)>,
    /// [`Landmarks::knee_left`].
    #[serde(default)]
    pub knee_left: Option<(f64, f64, f64)>,
    /// [`Landmarks::knee_right`].
    #[serde(default)]
    pub knee_right: Option<(f64, f64, f64)>,
    /// [`Landmarks::ankle_left`].
    #[serde(default)]
    pub ankle_left: Option<(f64, f64, f64)>,
    /// [`Landmarks::ankle_right`].
    #[serde(default)]
    pub ankle_right: Option<(f64, f64, f64)>,
}

impl LandmarkFile {
    /// Read a landmark file (RON; errors name the file, line, column and field).
    pub fn load(path: &Path) -> Result<LandmarkFile, FileError> {
        atelier_files::files::load_ron(path)
    }

    /// Replace the landmarks this file gives.
    pub fn apply(&self, l: &mut Landmarks) {
        let v = |p: (f64, f64, f64)| V3::new(p.0, p.1, p.2);
        let points: [(Given, &mut V3); 19] = [
            (self.crotch, &mut l.crotch),
            (self.armpit_left, &mut l.armpit_left),
            (self.armpit_right, &mut l.armpit_right),
            (self.neck_base, &mut l.neck_base),
            (self.chin, &mut l.chin),
            (self.shoulder_left, &mut l.shoulder_left),
            (self.shoulder_right, &mut l.shoulder_right),
            (self.elbow_left, &mut l.elbow_left),
            (self.elbow_right, &mut l.elbow_right),
            (self.wrist_left, &mut l.wrist_left),
            (self.wrist_right, &mut l.wrist_right),
            (self.hip_left, &mut l.hip_left),
            (self.hip_right, &mut l.hip_right),
            (self.knee_left, &mut l.knee_left),
            (self.knee_right, &mut l.knee_right),
            (self.ankle_left, &mut l.ankle_left),
            (self.ankle_right, &mut l.ankle_right),
            (None, &mut l.toe_left),
            (None, &mut l.toe_right),
        ];
        for (given, slot) in points {
            if let Some(p) = given {
                *slot = v(p);
            }
        }
        for (given, g) in [
            (self.hip_height, &mut l.hip),
            (self.waist_height, &mut l.waist),
            (self.bust_height, &mut l.bust),
            (self.neck_height, &mut l.neck),
        ] {
            if let Some(h) = given {
                g.height = h;
                g.centre.y = h;
            }
        }
    }
}

/// A point a landmark file may give.
type Given = Option<(f64, f64, f64)>;

/// A group of contours of one horizontal section that overlap (one piece of the body there;
/// contours overlap only where a body is made of overlapping closed parts).
#[derive(Clone, Debug)]
struct Blob {
    contours: Vec<usize>,
    bbox: [f64; 4],
    length: f64,
    centroid: V3,
}

/// The horizontal sections.
struct Sections {
    y: Vec<f64>,
    contours: Vec<Vec<Contour>>,
    blobs: Vec<Vec<Blob>>,
}

impl Sections {
    fn new(vertices: &[V3], triangles: &[[u32; 3]], step: f64) -> Sections {
        let (lo, hi) = vertices
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
                (a.0.min(p.y), a.1.max(p.y))
            });
        let n = ((hi - lo) / step).floor() as usize;
        let y: Vec<f64> = (0..n).map(|k| lo + (k as f64 + 0.5) * step).collect();
        let value: Vec<f64> = vertices.iter().map(|p| p.y).collect();
        let contours: Vec<Vec<Contour>> = Field::new(vertices, triangles, &value)
            .contours(&y)
            .into_iter()
            .map(|cs| cs.into_iter().filter(|c| c.closed).collect())
            .collect();
        let blobs = contours.iter().map(|cs| blobs_of(cs)).collect();
        Sections { y, contours, blobs }
    }

    /// Whether blob `a` of level `k` and blob `b` of level `k + 1` overlap (seen from above).
    fn linked(&self, k: usize, a: usize, b: usize) -> bool {
        let (ba, bb) = (&self.blobs[k][a], &self.blobs[k + 1][b]);
        boxes_overlap(&ba.bbox, &bb.bbox)
            && ba.contours.iter().any(|&i| {
                bb.contours
                    .iter()
                    .any(|&j| overlap_xz(&self.contours[k][i], &self.contours[k + 1][j]))
            })
    }

    /// The blobs of level `k + 1` over blob `a` of level `k`, largest first.
    fn successors(&self, k: usize, a: usize) -> Vec<usize> {
        let mut s: Vec<usize> = (0..self.blobs[k + 1].len())
            .filter(|&b| self.linked(k, a, b))
            .collect();
        s.sort_by(|&i, &j| {
            self.blobs[k + 1][j]
                .length
                .total_cmp(&self.blobs[k + 1][i].length)
        });
        s
    }

    fn points(&self, k: usize, b: usize) -> impl Iterator<Item = V3> + '_ {
        self.blobs[k][b]
            .contours
            .iter()
            .flat_map(move |&i| self.contours[k][i].points.iter().copied())
    }

    fn hull_girth(&self, k: usize, b: usize) -> f64 {
        hull_perimeter_xz(self.points(k, b))
    }
}

/// Group the contours of one level into blobs (union of overlapping contours).
fn blobs_of(cs: &[Contour]) -> Vec<Blob> {
    let n = cs.len();
    let boxes: Vec<[f64; 4]> = cs.iter().map(|c| bbox_xz(c.points.iter())).collect();
    let mut root: Vec<usize> = (0..n).collect();
    fn find(r: &mut [usize], mut i: usize) -> usize {
        while r[i] != i {
            r[i] = r[r[i]];
            i = r[i];
        }
        i
    }
    for i in 0..n {
        for j in i + 1..n {
            if boxes_overlap(&boxes[i], &boxes[j]) && overlap_xz(&cs[i], &cs[j]) {
                let (a, b) = (find(&mut root, i), find(&mut root, j));
                root[a] = b;
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut slot = vec![usize::MAX; n];
    for i in 0..n {
        let r = find(&mut root, i);
        if slot[r] == usize::MAX {
            slot[r] = groups.len();
            groups.push(Vec::new());
        }
        groups[slot[r]].push(i);
    }
    groups
        .into_iter()
        .map(|g| {
            let length: f64 = g.iter().map(|&i| cs[i].length()).sum();
            let centroid = g
                .iter()
                .map(|&i| cs[i].centroid() * cs[i].length())
                .sum::<V3>()
                / length.max(1e-300);
            let bbox = bbox_xz(g.iter().flat_map(|&i| cs[i].points.iter()));
            Blob {
                contours: g,
                bbox,
                length,
                centroid,
            }
        })
        .collect()
}

/// Find the landmarks of a closed, outward mesh of a body standing in an A- or T-pose.
pub fn find_landmarks(
    vertices: &[V3],
    triangles: &[[u32; 3]],
    opts: &ScanOptions,
) -> Result<Landmarks, ScanError> {
    let lost = |what: &'static str, why: String| ScanError::Landmark { what, why };
    let step = opts.step;
    let used: Vec<bool> = {
        let mut u = vec![false; vertices.len()];
        for &k in triangles.iter().flatten() {
            u[k as usize] = true;
        }
        u
    };
    let (floor, top) = vertices
        .iter()
        .zip(&used)
        .filter(|(_, u)| **u)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, (p, _)| {
            (a.0.min(p.y), a.1.max(p.y))
        });
    let height = top - floor;
    let sec = Sections::new(vertices, triangles, step);
    let nl = sec.y.len();
    if nl < 20 {
        return Err(lost("crotch", format!("only {nl} sections")));
    }
    // Area-weighted centre of the surface: the body's middle in x.
    let (mut cx, mut area) = (0.0, 0.0);
    for t in triangles {
        let [a, b, c] = t.map(|k| vertices[k as usize]);
        let w = 0.5 * (b - a).cross(&(c - a)).norm();
        cx += w * (a.x + b.x + c.x) / 3.0;
        area += w;
    }
    let cx = cx / area;

    // Legs: at a quarter of the height, the largest piece either side of the middle.
    let k0 = sec.y.partition_point(|&y| y < floor + 0.25 * height);
    let side_max = |k: usize, left: bool| {
        (0..sec.blobs[k].len())
            .filter(|&b| (sec.blobs[k][b].centroid.x > cx) == left)
            .max_by(|&a, &b| sec.blobs[k][a].length.total_cmp(&sec.blobs[k][b].length))
    };
    let (mut l, mut r) = match (side_max(k0, true), side_max(k0, false)) {
        (Some(l), Some(r)) => (l, r),
        _ => {
            return Err(lost(
                "crotch",
                format!(
                    "not two legs at a quarter of the height (y = {:.3} m)",
                    sec.y[k0]
                ),
            ));
        }
    };
    let leg_seed = [sec.blobs[k0][l].centroid, sec.blobs[k0][r].centroid];
    let mut k = k0;
    let (crotch, mut torso) = loop {
        if k + 1 >= nl {
            return Err(lost("crotch", "the legs never join".into()));
        }
        let (sl, sr) = (sec.successors(k, l), sec.successors(k, r));
        let (Some(&nl_), Some(&nr)) = (sl.first(), sr.first()) else {
            return Err(lost(
                "crotch",
                format!("a leg ends at y = {:.3} m", sec.y[k]),
            ));
        };
        if nl_ == nr || sl.contains(&nr) || sr.contains(&nl_) {
            let (bl, br) = (&sec.blobs[k][l], &sec.blobs[k][r]);
            let x = 0.5 * (bl.bbox[0] + br.bbox[1]);
            let z = 0.5 * (bl.centroid.z + br.centroid.z);
            break (V3::new(x, sec.y[k], z), nl_);
        }
        l = nl_;
        r = nr;
        k += 1;
    };
    // The trunk upward from the crotch; arms join it at the armpits.
    let k_crotch = k + 1;
    let mut central = vec![usize::MAX; nl];
    let mut armpit: [Option<(V3, V3)>; 2] = [None, None]; // (armpit point, seed on the arm)
    let mut k = k_crotch;
    loop {
        central[k] = torso;
        if k + 1 >= nl {
            break;
        }
        let succ = sec.successors(k, torso);
        let Some(&next) = succ.first() else { break };
        let t = &sec.blobs[k][torso];
        for (b, blob) in sec.blobs[k].iter().enumerate() {
            if b == torso || !sec.linked(k, b, next) {
                continue;
            }
            let side = usize::from(blob.centroid.x < t.centroid.x); // 0 left, 1 right
            if armpit[side].is_none() {
                let x = if side == 0 {
                    0.5 * (t.bbox[1] + blob.bbox[0])
                } else {
                    0.5 * (t.bbox[0] + blob.bbox[1])
                };
                armpit[side] = Some((V3::new(x, sec.y[k], blob.centroid.z), blob.centroid));
            }
        }
        torso = next;
        k += 1;
    }
    let [
        Some((armpit_left, arm_seed_l)),
        Some((armpit_right, arm_seed_r)),
    ] = armpit
    else {
        return Err(lost(
            if armpit[0].is_none() {
                "armpit_left"
            } else {
                "armpit_right"
            },
            "no arm joins the trunk above the crotch".into(),
        ));
    };
    // Girths of the trunk between the crotch and the lower armpit.
    let girth_at = |k: usize| Girth {
        height: sec.y[k],
        girth: sec.hull_girth(k, central[k]),
        centre: sec.blobs[k][central[k]].centroid,
    };
    let y_arm = armpit_left.y.min(armpit_right.y);
    let span = y_arm - crotch.y;
    let levels = |a: f64, b: f64| {
        let lo = sec.y.partition_point(|&y| y < a).max(k_crotch);
        let hi = sec.y.partition_point(|&y| y < b);
        (lo..hi).filter(|&k| central[k] != usize::MAX)
    };
    let pick = |a: f64, b: f64, largest: bool, what: &'static str| -> Result<Girth, ScanError> {
        levels(a, b)
            .map(girth_at)
            .max_by(|p, q| {
                let o = p.girth.total_cmp(&q.girth);
                if largest { o } else { o.reverse() }
            })
            .ok_or_else(|| {
                lost(
                    what,
                    format!("no trunk section between {a:.3} and {b:.3} m"),
                )
            })
    };
    let waist = pick(
        crotch.y + 0.35 * span,
        crotch.y + 0.85 * span,
        false,
        "waist",
    )?;
    // Prominences: the seat's farthest back, the bust's farthest forward.
    let prominent = |a: f64, b: f64, back: bool, what: &'static str| -> Result<Girth, ScanError> {
        levels(a, b)
            .map(|k| {
                let z = sec
                    .points(k, central[k])
                    .map(|p| if back { -p.z } else { p.z });
                (k, z.fold(f64::NEG_INFINITY, f64::max))
            })
            .max_by(|p, q| p.1.total_cmp(&q.1))
            .map(|(k, _)| girth_at(k))
            .ok_or_else(|| {
                lost(
                    what,
                    format!("no trunk section between {a:.3} and {b:.3} m"),
                )
            })
    };
    let hip = prominent(crotch.y, waist.height, true, "hip")?;
    let bust = prominent(waist.height, y_arm, false, "bust")?;
    let y_arm_hi = armpit_left.y.max(armpit_right.y);
    let neck = pick(y_arm_hi, top - 0.1 * height, false, "neck")?;
    // Neck base: the lowest section above the armpits within 20 % of the neck's girth; chin:
    // the first section above the neck whose girth exceeds it by 20 % (the jaw).
    let k_neck = sec.y.partition_point(|&y| y < neck.height);
    let k_base = levels(y_arm_hi, neck.height + 1e-9)
        .find(|&k| girth_at(k).girth <= 1.2 * neck.girth)
        .unwrap_or(k_neck);
    let neck_base = sec.blobs[k_base][central[k_base]].centroid;
    let k_chin = (k_neck..nl)
        .find(|&k| central[k] != usize::MAX && girth_at(k).girth > 1.2 * neck.girth)
        .ok_or_else(|| lost("chin", "no section above the neck is wider than it".into()))?;
    let chin = {
        let c = sec.blobs[k_chin][central[k_chin]].centroid;
        let front = sec
            .points(k_chin, central[k_chin])
            .map(|p| p.z)
            .fold(f64::NEG_INFINITY, f64::max);
        V3::new(c.x, sec.y[k_chin], front)
    };

    // Limbs.
    let adj = Adjacency::new(vertices.len(), triangles);
    let arm = |left: bool, pit: V3, seed: V3| -> Result<ArmMarks, ScanError> {
        let what = if left { "arm_left" } else { "arm_right" };
        let limb = Limb::new(
            vertices,
            triangles,
            &adj,
            |p| p.y < pit.y && ((p.x > pit.x) == left),
            seed,
            step,
            what,
        )?;
        arm_marks(&limb, pit, vertices, triangles, what)
    };
    let al = arm(true, armpit_left, arm_seed_l)?;
    let ar = arm(false, armpit_right, arm_seed_r)?;
    let leg = |left: bool, seed: V3| -> Result<LegMarks, ScanError> {
        let what = if left { "leg_left" } else { "leg_right" };
        let limb = Limb::new(
            vertices,
            triangles,
            &adj,
            |p| p.y < crotch.y && ((p.x > crotch.x) == left),
            seed,
            step,
            what,
        )?;
        leg_marks(&limb, &hip, floor, height, what)
    };
    let ll = leg(true, leg_seed[0])?;
    let lr = leg(false, leg_seed[1])?;
    Ok(Landmarks {
        crotch,
        armpit_left,
        armpit_right,
        hip,
        waist,
        bust,
        neck,
        neck_base,
        chin,
        shoulder_left: al.shoulder,
        shoulder_right: ar.shoulder,
        elbow_left: al.elbow,
        elbow_right: ar.elbow,
        wrist_left: al.wrist,
        wrist_right: ar.wrist,
        hand_tip_left: al.tip,
        hand_tip_right: ar.tip,
        hip_left: ll.hip,
        hip_right: lr.hip,
        knee_left: ll.knee,
        knee_right: lr.knee,
        ankle_left: ll.ankle,
        ankle_right: lr.ankle,
        toe_left: ll.tip,
        toe_right: lr.tip,
        height,
    })
}
