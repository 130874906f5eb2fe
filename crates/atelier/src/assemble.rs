//! A garment's panels as one cloth: the panels' topologies joined (no edge between panels) and
//! every seam — between panels, within a panel, and each dart's legs — as node pairs of the joint
//! cloth.

use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_grid::ClothTopology;
use atelier_grid::pattern::Garment;
use atelier_solver::{Cloth, ClothError};

/// A garment ready for the solver.
pub struct GarmentCloth {
    /// The cloth: all panels, one fabric.
    pub cloth: Cloth,
    /// First node of each panel in the joint cloth.
    pub offsets: Vec<u32>,
    /// Name of each panel.
    pub panel_names: Vec<String>,
    /// Node pairs to sew: seams then darts, in the joint cloth's numbering.
    pub pairs: Vec<(u32, u32)>,
    /// For each pair, the seam or dart it belongs to.
    pub pair_names: Vec<String>,
}

/// Why a garment cannot become a cloth.
#[derive(Debug, thiserror::Error)]
pub enum AssembleError {
    /// The cloth could not be built (fabric against topology).
    #[error(transparent)]
    Cloth(#[from] ClothError),
}

impl GarmentCloth {
    /// Join the panels of `garment` into one cloth of `fabric`.
    pub fn new(
        garment: &Garment,
        fabric: &Fabric,
        form: AnisotropyForm,
    ) -> Result<Self, AssembleError> {
        let topologies: Vec<&ClothTopology> = garment.panels.iter().map(|p| &p.topology).collect();
        let (topology, offsets) = ClothTopology::union(&topologies);
        let mut pairs = Vec::new();
        let mut pair_names = Vec::new();
        for seam in &garment.seams {
            let (oa, ob) = (offsets[seam.panel_a], offsets[seam.panel_b]);
            for &(a, b) in &seam.pairs {
                if a + oa != b + ob {
                    pairs.push((a + oa, b + ob));
                    pair_names.push(seam.name.clone());
                }
            }
        }
        for (panel, o) in garment.panels.iter().zip(&offsets) {
            for dart in &panel.darts {
                for &(a, b) in &dart.pairs {
                    pairs.push((a + o, b + o));
                    pair_names.push(format!("{}: {}", panel.name, dart.name));
                }
            }
        }
        Ok(Self {
            cloth: Cloth::new(topology, fabric, form)?,
            panel_names: garment.panels.iter().map(|p| p.name.clone()).collect(),
            offsets,
            pairs,
            pair_names,
        })
    }
}
