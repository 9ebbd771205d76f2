//! Energy diagnostics of a model state (the curves of the paper's Figs. 1, 4 and 5).

use crate::model::ClothModel;
use crate::vecs::v3s;

/// Energy of a state, in joules.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energy {
    /// `sum 1/2 m |v|^2` over free particles.
    pub kinetic: f64,
    /// `-sum m g . x` over free particles.
    pub gravity: f64,
    /// `sum 1/2 c^2 / eps` over soft links plus the StVK energy of the membrane triangles
    /// (`1/2 c' C^-1 c`).
    pub elastic: f64,
    /// The sum of the three.
    pub total: f64,
}

impl Energy {
    /// The energy of `model`'s current state.
    pub fn of(model: &ClothModel) -> Self {
        let mut kinetic = 0.0;
        let mut gravity = 0.0;
        let g = model.g();
        for ((x, v), &w) in model.xs().iter().zip(model.vs()).zip(&model.inv_mass) {
            if w > 0.0 {
                kinetic += 0.5 * v.norm_squared() / w;
                gravity -= g.dot(x) / w;
            }
        }
        let elastic = elastic_energy(model, &model.x);
        Self {
            kinetic,
            gravity,
            elastic,
            total: kinetic + gravity + elastic,
        }
    }
}

/// Elastic energy `1/2 c' C^-1 c` of `model`'s constraints at positions `x` (soft links and
/// membrane triangles).
pub fn elastic_energy(model: &ClothModel, x: &[[f64; 3]]) -> f64 {
    let xv = v3s(x);
    model
        .links
        .iter()
        .filter(|l| l.compliance > 0.0)
        .map(|l| {
            let c = (xv[l.i] - xv[l.j]).norm() - l.rest;
            0.5 * c * c / l.compliance
        })
        .sum::<f64>()
        + model.tris.iter().map(|t| t.energy(x)).sum::<f64>()
}
