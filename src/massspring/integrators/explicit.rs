//! Forward and symplectic Euler (the course notes' first driver).

use super::{set_kinematics, State, StepStats};
use crate::massspring::forces::total_forces;
use crate::scene::massspring::{System, V3};

/// Forward Euler: `x += h v; v += h f(x, v) / m` for the free particles,
/// then the kinematic particles are placed at `t + h`.
pub fn forward_euler(sys: &System, s: &mut State, h: f64) -> StepStats {
    let mut f = vec![V3::zeros(); sys.len()];
    total_forces(sys, &s.x, &s.v, &mut f);
    for (i, fi) in f.iter().enumerate() {
        if sys.is_free(i) {
            s.x[i] += s.v[i] * h;
            s.v[i] += fi * (h / sys.masses[i]);
        }
    }
    set_kinematics(sys, s.t + h, &mut s.x, &mut s.v);
    StepStats::new(h)
}

/// Symplectic (semi-implicit) Euler: `v += h f(x, v) / m; x += h v`.
pub fn symplectic_euler(sys: &System, s: &mut State, h: f64) -> StepStats {
    let mut f = vec![V3::zeros(); sys.len()];
    total_forces(sys, &s.x, &s.v, &mut f);
    for (i, fi) in f.iter().enumerate() {
        if sys.is_free(i) {
            s.v[i] += fi * (h / sys.masses[i]);
            s.x[i] += s.v[i] * h;
        }
    }
    set_kinematics(sys, s.t + h, &mut s.x, &mut s.v);
    StepStats::new(h)
}
