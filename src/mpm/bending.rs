//! Rest state of the bending energy: the discrete curvature of a turning
//! angle and the rest curvature and Voronoi length of every vertex, after
//! discrete elastic rods (Bergou et al. 2008) in 2D (the energy and its
//! forces are in [`super::vertex_forces`]). The particle store keeps one
//! [`BendRest`] per vertex; it depends on this module, not on the forces.

use crate::math::{cross, Vec2};

/// Rest data of the bending energy at one vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BendRest {
    /// Rest curvature `kappa0 = 2 tan(theta0 / 2)`.
    pub kappa0: f64,
    /// `1 / l` with `l` the rest Voronoi length; 0 at yarn ends (no bending).
    pub inv_len: f64,
}

impl BendRest {
    /// Rest data at a vertex between edges `e1` (incoming) and `e2` (outgoing).
    pub fn new(e1: Vec2, e2: Vec2) -> Self {
        BendRest {
            kappa0: curvature(e1, e2),
            inv_len: 2.0 / (e1.norm() + e2.norm()),
        }
    }
}

/// `2 tan(theta / 2)` of the turning angle from edge `e1` to edge `e2`.
#[inline(always)]
pub fn curvature(e1: Vec2, e2: Vec2) -> f64 {
    let d = e1.norm() * e2.norm() + e1.dot(&e2);
    if d > 0.0 {
        2.0 * cross(e1, e2) / d
    } else {
        0.0
    }
}

/// Rest bending data of a yarn's vertices `curve`: interior vertices get
/// their rest curvature and Voronoi length, the two ends none.
pub fn rest_of_curve(curve: &[Vec2]) -> Vec<BendRest> {
    let n = curve.len();
    (0..n)
        .map(|i| {
            if i == 0 || i + 1 == n {
                BendRest::default()
            } else {
                BendRest::new(curve[i] - curve[i - 1], curve[i + 1] - curve[i])
            }
        })
        .collect()
}
