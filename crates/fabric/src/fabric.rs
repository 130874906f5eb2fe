//! A fabric in SI: mass, thickness, friction, the tensile loop and the bending spindle in the four
//! measured directions, and the per-angle [`MaterialTable`] the solver looks edges up in.

use std::collections::HashMap;
use std::path::Path;

use crate::anisotropy::{self, AnisotropyForm, Directions, canonical_angle};
use crate::bending::Spindle;
use crate::error::{ErrorKind, FileError, InvalidValue};
use crate::files;
use crate::plausibility::{self, FabricClass, PlausibilityWarning};
use crate::shear::{ShearCurve, ShearLoop};
use crate::spec::{BendingSpec, FabricSpec, Provenance, ShearSpec, TensileSpec};
use crate::tensile::{Branch, TABLE_SEGMENTS, TensileLoop, TensileState};
use crate::units;

/// Largest dip of an interpolated tensile branch, as a fraction of its apex strain, that
/// [`Fabric::tensile_at`] repairs by a running maximum rather than rejecting.
pub const MAX_MONOTONE_REPAIR: f64 = 0.01;

/// Standard gravity, m/s² (used for weight per area and bending lengths).
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Default shear locking angle (rad): the trellis angle at which the yarns of a woven fabric
/// jam. Typical woven fabrics lock between 30° and 50°; 40° is a banded assumption, not a
/// measurement (set `locking_angle_deg` in the fabric file when it is known).
pub const DEFAULT_LOCKING_ANGLE: f64 = 40.0 * std::f64::consts::PI / 180.0;

/// The KES-FB1 standard pretension, 10 gf/cm, in N/m; as a shear stiffness (its T·tan γ term
/// per radian) it is 0.1745 gf/(cm·deg) of every published G.
pub const KES_PRETENSION: f64 = 10.0 * units::FORCE_PER_WIDTH;

/// KES shear values in SI (as the file gives them, or fitted to its measured loop), with the
/// locking angle that bounds the trellis shear of the derived bias loop. [`Shear::to_loop`] is
/// the loop as KES-FB1 reads it; [`Shear::to_material_loop`] the share a cloth's cells carry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shear {
    /// Shear stiffness G, N/(m·rad).
    pub stiffness: f64,
    /// Hysteresis width 2HG at 0.5°, N/m.
    pub hysteresis: f64,
    /// Hysteresis width 2HG5 at 5°, N/m: the shear loop's width from 5° on (the derived bias loop
    /// uses 2HG only).
    pub hysteresis_5deg: Option<f64>,
    /// Locking angle γ_lock, rad, in (0, π/2).
    pub locking_angle: f64,
}

impl Shear {
    /// From the file's shear section: its KES values, or those fitted to its measured loop
    /// ([`ShearSpec::kes_values`]). Errors when the section gives neither or both, or when its
    /// loop is invalid.
    pub fn from_spec(s: &ShearSpec) -> Result<Self, InvalidValue> {
        s.to_loop()?;
        let k = s.kes_values()?;
        Ok(Self {
            stiffness: units::shear_stiffness_from_kes(k.g_gf_cm_deg),
            hysteresis: units::force_from_kes(k.two_hg_gf_cm),
            hysteresis_5deg: k.two_hg5_gf_cm.map(units::force_from_kes),
            locking_angle: s
                .locking_angle_deg
                .map_or(DEFAULT_LOCKING_ANGLE, f64::to_radians),
        })
    }

    /// The reconstructed KES-FB1 loop of these values ([`ShearLoop::from_kes`]): the loop as
    /// the instrument reads it, pretension term included.
    pub fn to_loop(&self) -> Result<ShearLoop, InvalidValue> {
        ShearLoop::from_kes(self.stiffness, self.hysteresis, self.hysteresis_5deg)
    }

    /// The fabric's own share of the loop: G less the pretension term T = [`KES_PRETENSION`]
    /// (per radian) that every KES-FB1 reading contains (the specimen's warp, held at T between
    /// the clamps and tilted by γ, pulls the clamp back by T·tan γ). The widths are untouched
    /// (the term is elastic). In a cloth model the tensioned yarns supply that term themselves,
    /// so the cells must carry only this loop. An `Inconsistent` error when G ≤ T (a KES G below
    /// 0.1745 gf/(cm·deg) cannot have been read at the standard pretension).
    pub fn to_material_loop(&self) -> Result<ShearLoop, InvalidValue> {
        let g = self.stiffness - KES_PRETENSION;
        if g <= 0.0 {
            return Err(InvalidValue::new(
                ErrorKind::Inconsistent,
                "g",
                format!(
                    "G = {:.4} gf/(cm·deg) is not above the pretension term T·π/180 = {:.4} \
                     gf/(cm·deg) that a KES-FB1 reading at 10 gf/cm contains",
                    units::shear_stiffness_to_kes(self.stiffness),
                    units::shear_stiffness_to_kes(KES_PRETENSION)
                ),
            ));
        }
        ShearLoop::from_kes(g, self.hysteresis, self.hysteresis_5deg)
    }

    /// Shear angle (rad) on loading at shear force per width `tau` (N/m): the bilinear KES loop
    /// `τ = Gγ + HG` (sticking until τ exceeds HG), saturated smoothly at the locking angle,
    /// `γ = γ_lock·tanh(γ_lin/γ_lock)`, which keeps the slope G at small angles.
    pub fn loading_angle(&self, tau: f64) -> f64 {
        self.lock((tau - 0.5 * self.hysteresis).max(0.0) / self.stiffness)
    }

    /// Shear angle on unloading from the shear force `tau_max`: the bilinear loop's falling branch
    /// `τ = Gγ − HG`, capped at the angle reached at `tau_max`, saturated like the loading branch.
    pub fn unloading_angle(&self, tau: f64, tau_max: f64) -> f64 {
        let lin_max = (tau_max - 0.5 * self.hysteresis).max(0.0) / self.stiffness;
        self.lock(((tau + 0.5 * self.hysteresis) / self.stiffness).min(lin_max))
    }

    fn lock(&self, gamma_linear: f64) -> f64 {
        self.locking_angle * (gamma_linear / self.locking_angle).tanh()
    }
}

/// Strain along the bias of a pin-jointed (trellis) weave sheared by γ: the diagonal of a unit
/// rhombus, `√(1 + sin γ) − 1` (≈ γ/2 for small γ).
pub fn trellis_strain(gamma: f64) -> f64 {
    (1.0 + gamma.sin()).sqrt() - 1.0
}

/// The bias (45°) tensile loop implied by warp, weft and shear data (`method.md` §1.4,
/// generalised to the whole curve). Uniaxial force f along 45° puts f/2 on each yarn direction
/// and a shear force f/2 on the weave; with ν ≈ 0 the bias strain is
/// `ε₄₅(f) = ½ φ_v(f/2) + ½ φ_u(f/2) + s(γ(f/2))`, with s the trellis strain of the shear angle.
/// At small strain this is `1/E₄₅ = ¼ (1/E_v + 1/E_u + 1/G)`. The shear angle follows the bilinear
/// KES shear loop (half-width HG = 2HG/2) and saturates at the locking angle, so the bias strain
/// stays finite (about 30 % at Fm for a 40° lock) instead of growing linearly without bound. On
/// unloading the yarn terms follow their minor loops from f_max/2 (thesis (40)) and γ its
/// unloading branch, so the bias loop closes at its apex.
pub fn bias_from_shear(
    warp: &TensileLoop,
    weft: &TensileLoop,
    shear: &Shear,
) -> Result<TensileLoop, InvalidValue> {
    let f_max = warp.max_force().min(weft.max_force());
    let turn = |l: &TensileLoop| {
        let mut s = TensileState::VIRGIN;
        s.update(l, 0.5 * f_max);
        s
    };
    let (turn_v, turn_u) = (turn(warp), turn(weft));
    TensileLoop::from_fn(f_max, |f| {
        let tau = 0.5 * f;
        let up = 0.5 * (warp.strain(Branch::Loading, tau) + weft.strain(Branch::Loading, tau))
            + trellis_strain(shear.loading_angle(tau));
        let down = 0.5 * (turn_v.strain(warp, tau) + turn_u.strain(weft, tau))
            + trellis_strain(shear.unloading_angle(tau, 0.5 * f_max));
        (up, down)
    })
    .map_err(|e| e.within("shear"))
}

/// The bias (45°) tensile loop of the yarns alone: a uniaxial force f along 45° puts f/2 on
/// each yarn direction, `ε₄₅(f) = ½ φ_v(f/2) + ½ φ_u(f/2)` (ν ≈ 0), without the trellis shear of
/// [`bias_from_shear`] — for a model whose cells carry the shear themselves (the solver's shear
/// constraints, `method.md` §2b), where the fabric's own bias curve would count the shear twice.
pub fn bias_from_yarns(
    warp: &TensileLoop,
    weft: &TensileLoop,
) -> Result<TensileLoop, InvalidValue> {
    let rigid = Shear {
        stiffness: f64::INFINITY,
        hysteresis: 0.0,
        hysteresis_5deg: None,
        locking_angle: DEFAULT_LOCKING_ANGLE,
    };
    bias_from_shear(warp, weft, &rigid)
}

/// A fabric's mechanics in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct Fabric {
    /// Name.
    pub name: String,
    /// Provenance of the values.
    pub provenance: Provenance,
    /// Class for the plausibility bands, if stated.
    pub class: Option<FabricClass>,
    /// Mass per area, kg/m².
    pub mass_per_area: f64,
    /// Thickness, m.
    pub thickness: f64,
    /// Static friction coefficient on itself.
    pub friction: f64,
    /// Tensile loops in the measured directions (bias ones measured or derived).
    pub tensile: Directions<TensileLoop>,
    /// Bending characteristics in the measured directions (bias ones measured or derived).
    pub bending: Directions<Spindle>,
    /// KES shear values, if the file has a shear section (given, or fitted to a measured loop).
    pub shear: Option<Shear>,
}

impl ShearCurve {
    /// Build from a fabric's loading branches (the 45° bias; 135° is not used): the shear its
    /// tensile loops imply ([`ShearCurve::from_tensile`]).
    pub fn from_fabric(fabric: &Fabric) -> Self {
        Self::from_tensile(&fabric.tensile)
    }
}

impl Fabric {
    /// Load a fabric file (RON).
    pub fn load(path: &Path) -> Result<Self, FileError> {
        let spec: FabricSpec = files::load_ron(path)?;
        Self::from_spec(&spec).map_err(|e| FileError::from_invalid(path, e))
    }

    /// Parse fabric RON text; `file` names the source in errors.
    pub fn from_ron_str(text: &str, file: &Path) -> Result<Self, FileError> {
        let spec: FabricSpec = files::parse_ron(text, file)?;
        Self::from_spec(&spec).map_err(|e| FileError::from_invalid(file, e))
    }

    /// Convert a fabric description (KES units) to SI, synthesising curves from summary values,
    /// deriving the 45° tensile loop from shear and the bias bending from warp and weft where they
    /// are not given.
    pub fn from_spec(spec: &FabricSpec) -> Result<Self, InvalidValue> {
        let tensile_of = |t: &TensileSpec, field: &str| -> Result<TensileLoop, InvalidValue> {
            match t {
                TensileSpec::Kes(k) => TensileLoop::from_summary(&k.summary()),
                TensileSpec::Measured(m) => m.to_loop(),
            }
            .map_err(|e| e.within(field))
        };
        let bending_of = |b: &BendingSpec, field: &str| -> Result<Spindle, InvalidValue> {
            match b {
                BendingSpec::Kes(k) => Spindle::from_kes(k.b_gf_cm2_cm, k.two_hb_gf_cm_cm),
                BendingSpec::Measured(m) => m.fit().map(|f| f.spindle),
            }
            .map_err(|e| e.within(field))
        };
        let warp = tensile_of(&spec.tensile.warp, "tensile.warp")?;
        let weft = tensile_of(&spec.tensile.weft, "tensile.weft")?;
        let shear = spec
            .shear
            .as_ref()
            .map(Shear::from_spec)
            .transpose()
            .map_err(|e| e.within("shear"))?;
        let bias45 = match (&spec.tensile.bias45, &shear) {
            (Some(t), _) => tensile_of(t, "tensile.bias45")?,
            (None, Some(s)) => bias_from_shear(&warp, &weft, s)?,
            (None, None) => {
                return Err(InvalidValue::new(
                    ErrorKind::MissingField,
                    "tensile.bias45",
                    "no bias tensile data: give measured 45° curves or a `shear` section",
                ));
            }
        };
        let bias135 = match &spec.tensile.bias135 {
            Some(t) => tensile_of(t, "tensile.bias135")?,
            None => bias45.clone(),
        };
        let bwarp = bending_of(&spec.bending.warp, "bending.warp")?;
        let bweft = bending_of(&spec.bending.weft, "bending.weft")?;
        let b45 = match &spec.bending.bias45 {
            Some(b) => bending_of(b, "bending.bias45")?,
            None => Spindle::new(
                anisotropy::huber_bias(bwarp.rigidity(), bweft.rigidity()),
                anisotropy::huber_bias(bwarp.residual_moment(), bweft.residual_moment()),
            )
            .map_err(|e| e.within("bending.bias45"))?,
        };
        let b135 = match &spec.bending.bias135 {
            Some(b) => bending_of(b, "bending.bias135")?,
            None => b45,
        };
        Ok(Self {
            name: spec.name.clone(),
            provenance: spec.provenance.clone(),
            class: spec.class,
            mass_per_area: units::mass_per_area_from_kes(spec.mass_per_area_mg_cm2),
            thickness: units::thickness_from_kes(spec.thickness_mm),
            friction: spec.friction,
            tensile: Directions {
                warp,
                weft,
                bias45,
                bias135,
            },
            bending: Directions {
                warp: bwarp,
                weft: bweft,
                bias45: b45,
                bias135: b135,
            },
            shear,
        })
    }

    /// Weight per area w = m_A·g, N/m².
    pub fn weight_per_area(&self) -> f64 {
        self.mass_per_area * STANDARD_GRAVITY
    }

    /// Bending length c = (B/w)^(1/3) at material angle `theta` (m), the cantilever's scale.
    pub fn bending_length(&self, theta: f64, form: AnisotropyForm) -> Result<f64, InvalidValue> {
        Ok((self.bending_at(theta, form)?.rigidity() / self.weight_per_area()).cbrt())
    }

    /// The tensile loop at material angle `theta` (rad from the warp), interpolated knot by knot
    /// from the warp, weft and bias loops (`method.md` §1.3) up to the smallest apex force of the
    /// three. Build once per distinct angle ([`MaterialTable`]), never per edge per step.
    ///
    /// The interpolation weights change sign inside each quadrant, so an interpolated branch can
    /// dip slightly (the thesis form on the denim fixture at 56.25°: by 5e-5 of its strain near
    /// Fm). Such dips are repaired by a running maximum along each branch (and the unloading
    /// branch is kept at or above the loading one); a repair larger than
    /// [`MAX_MONOTONE_REPAIR`] of the apex strain is an error. [`MaterialTable::repair`] reports
    /// the size of each repair.
    pub fn tensile_at(
        &self,
        theta: f64,
        form: AnisotropyForm,
    ) -> Result<TensileLoop, InvalidValue> {
        self.tensile_at_repaired(theta, form).map(|(l, _)| l)
    }

    fn tensile_at_repaired(
        &self,
        theta: f64,
        form: AnisotropyForm,
    ) -> Result<(TensileLoop, f64), InvalidValue> {
        self.tensile_from_knots(theta, form, &self.direction_knots(theta))
    }

    /// The warp, weft and bias strains (the bias serving `theta`) on both major branches at
    /// the force knots of the common range: what every angle served by that bias interpolates.
    fn direction_knots(&self, theta: f64) -> DirectionKnots {
        let d = &self.tensile;
        let bias = d.bias_for(theta);
        let f_max = d
            .warp
            .max_force()
            .min(d.weft.max_force())
            .min(bias.max_force());
        let mut strains = [Vec::new(), Vec::new()];
        for (branch, list) in [Branch::Loading, Branch::Unloading]
            .into_iter()
            .zip(strains.iter_mut())
        {
            *list = (0..=TABLE_SEGMENTS)
                .map(|j| {
                    let a = j as f64 / TABLE_SEGMENTS as f64;
                    let f = f_max * a * a;
                    [
                        d.warp.strain(branch, f),
                        d.weft.strain(branch, f),
                        bias.strain(branch, f),
                    ]
                })
                .collect();
        }
        DirectionKnots { f_max, strains }
    }

    /// [`Fabric::tensile_at`] from the directions' knots (`knots` from
    /// [`Fabric::direction_knots`] at an angle the same bias serves), with the largest
    /// monotonicity repair over the apex strain.
    fn tensile_from_knots(
        &self,
        theta: f64,
        form: AnisotropyForm,
        knots: &DirectionKnots,
    ) -> Result<(TensileLoop, f64), InvalidValue> {
        let f_max = knots.f_max;
        let deg = theta.to_degrees();
        let weights = anisotropy::weights(theta);
        let mut tables = [
            Vec::with_capacity(TABLE_SEGMENTS + 1),
            Vec::with_capacity(TABLE_SEGMENTS + 1),
        ];
        for j in 0..=TABLE_SEGMENTS {
            let a = j as f64 / TABLE_SEGMENTS as f64;
            let f = f_max * a * a;
            for ((branch, table), strains) in [Branch::Loading, Branch::Unloading]
                .into_iter()
                .zip(tables.iter_mut())
                .zip(&knots.strains)
            {
                let [warp, weft, bias] = strains[j];
                let tensile_form = form.for_tensile();
                let Some(v) =
                    anisotropy::interpolate_weighted(tensile_form, weights, warp, weft, bias)
                else {
                    let message = format!(
                        "the {form:?} form gives no positive strain at θ = {deg:.2}°, \
                         f = {f:.4} N/m ({branch:?})"
                    );
                    return Err(InvalidValue::new(ErrorKind::OutOfRange, "tensile", message));
                };
                table.push(v);
            }
        }
        let [mut load, mut unload] = tables;
        let mut repair: f64 = 0.0;
        for table in [&mut load, &mut unload] {
            for j in 1..table.len() {
                if table[j] < table[j - 1] {
                    repair = repair.max(table[j - 1] - table[j]);
                    table[j] = table[j - 1];
                }
            }
        }
        for (u, l) in unload.iter_mut().zip(&load) {
            if *u < *l {
                repair = repair.max(*l - *u);
                *u = *l;
            }
        }
        let apex = load[TABLE_SEGMENTS];
        if repair > MAX_MONOTONE_REPAIR * apex {
            return Err(InvalidValue::new(
                ErrorKind::NonMonotone,
                "tensile",
                format!(
                    "the {form:?} form at θ = {deg:.2}° gives branches that fall or cross by {:.3} % of \
                     the apex strain (more than {} % cannot be repaired); try the other form",
                    100.0 * repair / apex,
                    100.0 * MAX_MONOTONE_REPAIR
                ),
            ));
        }
        let l = TensileLoop::from_knots(f_max, load, unload).map_err(|e| {
            InvalidValue::new(
                e.kind,
                "tensile",
                format!("at θ = {deg:.2}° ({form:?} form): {}", e.message),
            )
        })?;
        Ok((l, repair / apex))
    }

    /// The bending characteristic at material angle `theta`: B and M₀ each interpolated with
    /// `form` (so every direction keeps the spindle shape of assumption (I)).
    pub fn bending_at(&self, theta: f64, form: AnisotropyForm) -> Result<Spindle, InvalidValue> {
        let d = &self.bending;
        let bias = d.bias_for(theta);
        let deg = theta.to_degrees();
        let undefined = |what: &str| {
            InvalidValue::new(
                ErrorKind::OutOfRange,
                "bending",
                format!("the {form:?} form gives no valid {what} at θ = {deg:.2}°"),
            )
        };
        let b = anisotropy::interpolate(
            form.for_bending(),
            theta,
            d.warp.rigidity(),
            d.weft.rigidity(),
            bias.rigidity(),
        )
        .ok_or_else(|| undefined("rigidity"))?;
        let m0 = anisotropy::interpolate(
            form.for_bending(),
            theta,
            d.warp.residual_moment(),
            d.weft.residual_moment(),
            bias.residual_moment(),
        )
        .ok_or_else(|| undefined("residual moment"))?;
        Spindle::new(b, m0).map_err(|e| e.within("bending"))
    }

    /// The in-plane shear characteristic with its hysteresis (KES-FB1), for the solver's shear
    /// angle per cell. From the shear section when the file has one (its KES values, or those
    /// fitted to its measured loop); otherwise derived from the warp, weft and 45° bias loading
    /// branches by inverting the trellis relation of [`bias_from_shear`] ([`ShearCurve::to_loop`]:
    /// G the mean slope between 0.5° and 5°, HG the stick, the width constant). Errors only when
    /// the `shear` values were set by hand to something invalid (G ≤ 0, a falling branch).
    pub fn shear_loop(&self) -> Result<ShearLoop, InvalidValue> {
        match &self.shear {
            Some(s) => s.to_loop().map_err(|e| e.within("shear")),
            None => Ok(ShearCurve::from_fabric(self).to_loop()),
        }
    }

    /// The loop the cloth's cells carry: [`Fabric::shear_loop`] less the KES pretension term
    /// when the loop comes from KES-FB1 values or a measured FB1 record
    /// ([`Shear::to_material_loop`]); a loop derived from the bias tensile branches has no such
    /// term and is returned as it is. `docs/fabric.md` §9 ("The pretension term") and
    /// `docs/validation.md` say why.
    pub fn material_shear_loop(&self) -> Result<ShearLoop, InvalidValue> {
        match &self.shear {
            Some(s) => s.to_material_loop().map_err(|e| e.within("shear")),
            None => Ok(ShearCurve::from_fabric(self).to_loop()),
        }
    }

    /// Values outside the typical bands of the fabric's class (see [`plausibility::check`]).
    pub fn plausibility(&self) -> Vec<PlausibilityWarning> {
        plausibility::check(self)
    }
}

/// The warp, weft and bias strains on the loading and unloading branches at the force knots
/// `f_max·(j/N)²` of one bias side (`Fabric::direction_knots`).
struct DirectionKnots {
    f_max: f64,
    /// Per branch (loading, unloading), per knot: warp, weft, bias.
    strains: [Vec<[f64; 3]>; 2],
}

/// The characteristics at every distinct material angle of a grid's edges, built once.
/// Angles equal modulo 180° (to 1e-9 rad) share an entry.
#[derive(Clone, Debug)]
pub struct MaterialTable {
    form: AnisotropyForm,
    angles: Vec<f64>,
    tensile: Vec<TensileLoop>,
    repairs: Vec<f64>,
    bending: Vec<Spindle>,
}

impl MaterialTable {
    /// Angles are binned to this resolution (0.1°, rad) before they are interpolated: a cut
    /// garment's curved grid gives nearly every edge its own angle. Half a bin changes a
    /// fixture's loading strain by at most 1 % of itself (4.9e-4 in strain) and its bending
    /// rigidity by 0.06 % (test `half_an_angle_bin_changes_the_characteristics_little`).
    pub const ANGLE_RESOLUTION: f64 = std::f64::consts::PI / 1800.0;

    /// Build the table for `edge_angles` (rad from the warp, binned to
    /// [`MaterialTable::ANGLE_RESOLUTION`]); returns it and, for each input angle, the index of
    /// its entry.
    pub fn build(
        fabric: &Fabric,
        form: AnisotropyForm,
        edge_angles: &[f64],
    ) -> Result<(Self, Vec<u32>), InvalidValue> {
        let mut index_of: HashMap<i64, u32> = HashMap::new();
        let mut table = Self {
            form,
            angles: Vec::new(),
            tensile: Vec::new(),
            repairs: Vec::new(),
            bending: Vec::new(),
        };
        let mut indices = Vec::with_capacity(edge_angles.len());
        // The directions' knots per bias (45°, 135°), made once for all the angles it serves.
        let mut knots: [Option<DirectionKnots>; 2] = [None, None];
        for (e, &theta) in edge_angles.iter().enumerate() {
            if !theta.is_finite() {
                return Err(InvalidValue::new(
                    ErrorKind::NotFinite,
                    format!("[{e}]"),
                    format!("edge angle {theta}"),
                ));
            }
            let key = (canonical_angle(theta) / Self::ANGLE_RESOLUTION).round() as i64;
            let canon = canonical_angle(key as f64 * Self::ANGLE_RESOLUTION);
            let key = (canon / Self::ANGLE_RESOLUTION).round() as i64;
            let idx = match index_of.get(&key) {
                Some(&i) => i,
                None => {
                    let i = table.angles.len() as u32;
                    let side = anisotropy::bias_side(canon);
                    let k = knots[side].get_or_insert_with(|| fabric.direction_knots(canon));
                    let (l, repair) = fabric.tensile_from_knots(canon, form, k)?;
                    table.tensile.push(l);
                    table.repairs.push(repair);
                    table.bending.push(fabric.bending_at(canon, form)?);
                    table.angles.push(canon);
                    index_of.insert(key, i);
                    i
                }
            };
            indices.push(idx);
        }
        Ok((table, indices))
    }

    /// The same table with every tensile loop transformed by `f` (for example a linear toe).
    #[must_use]
    pub fn map_tensile(mut self, f: impl Fn(&TensileLoop) -> TensileLoop) -> Self {
        for l in &mut self.tensile {
            *l = f(l);
        }
        self
    }

    /// The interpolation law used.
    pub fn form(&self) -> AnisotropyForm {
        self.form
    }

    /// Number of distinct angles.
    pub fn len(&self) -> usize {
        self.angles.len()
    }

    /// Whether the table is empty.
    pub fn is_empty(&self) -> bool {
        self.angles.is_empty()
    }

    /// Canonical angle (rad, in [0, π)) of entry `i`.
    pub fn angle(&self, i: u32) -> f64 {
        self.angles[i as usize]
    }

    /// Tensile loop of entry `i`.
    pub fn tensile(&self, i: u32) -> &TensileLoop {
        &self.tensile[i as usize]
    }

    /// Largest monotonicity repair of entry `i`'s tensile loop, as a fraction of its apex strain
    /// (0 when the interpolated branches were monotone as computed).
    pub fn repair(&self, i: u32) -> f64 {
        self.repairs[i as usize]
    }

    /// Bending characteristic of entry `i`.
    pub fn bending(&self, i: u32) -> &Spindle {
        &self.bending[i as usize]
    }
}
