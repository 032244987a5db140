//! The FMI 3.0 Float64 array outputs of the yarn bundle: per yarn, the
//! positions and the velocities of its vertices (`[n, 2]`, row-major: x, y
//! of vertex 0, then of vertex 1, ...). Their sizes are the bundled scene's
//! vertex counts, fixed when the FMU is generated.

use yarnsim::scene::YarnScene;

use crate::model_description::{ArrayVariable, VR_ARRAY_BASE};

use super::YarnModel;

/// `yarn[i].positions` has `VR_ARRAY_BASE + 2 i`, `yarn[i].velocities`
/// the next value reference.
pub fn array_vr(yarn: usize, velocities: bool) -> u32 {
    VR_ARRAY_BASE + 2 * yarn as u32 + velocities as u32
}

/// The yarn and the kind (true: velocities) of an array value reference.
fn array_of(vr: u32, yarns: usize) -> Option<(usize, bool)> {
    let k = vr.checked_sub(VR_ARRAY_BASE)? as usize;
    (k / 2 < yarns).then_some((k / 2, k % 2 == 1))
}

/// The name of the array `vr` of a bundle of `yarns` yarns
/// (`yarn[i].positions` or `yarn[i].velocities`).
pub fn array_name(vr: u32, yarns: usize) -> Option<String> {
    let (i, velocities) = array_of(vr, yarns)?;
    let what = if velocities {
        "velocities"
    } else {
        "positions"
    };
    Some(format!("yarn[{i}].{what}"))
}

/// The array outputs of the FMU for this scene, in `ModelVariables` order;
/// their values after initialization depend on `initial` (the `scene`
/// parameter: the initial positions and velocities are the scene's).
pub fn yarn_arrays(scene: &YarnScene, initial: &[u32]) -> Vec<ArrayVariable> {
    let mut a = Vec::new();
    for (i, curve) in scene.curves().iter().enumerate() {
        let n = curve.len();
        for (velocities, what, unit) in [(false, "positions", "m"), (true, "velocities", "m/s")] {
            a.push(ArrayVariable {
                name: format!("yarn[{i}].{what}"),
                vr: array_vr(i, velocities),
                dims: vec![n, 2],
                unit: Some(unit),
                description: format!(
                    "Yarn {i}: the {what} of its {n} vertices, x and y of each (row-major {n} x 2)"
                ),
                initial: initial.to_vec(),
            });
        }
    }
    a
}

impl YarnModel {
    /// The vertex range of yarn `y` of the running simulation.
    fn vertices(&self, y: usize) -> std::ops::Range<usize> {
        let r = &self.sim.particles().yarn_vertices;
        r[y]..r[y + 1]
    }

    pub fn array_len(&self, vr: u32) -> Option<usize> {
        let (y, _) = array_of(vr, self.sim.num_yarns())?;
        Some(2 * self.vertices(y).len())
    }

    pub fn write_array(&self, vr: u32, out: &mut [f64]) -> bool {
        let Some((y, velocities)) = array_of(vr, self.sim.num_yarns()) else {
            return false;
        };
        let range = self.vertices(y);
        if out.len() != 2 * range.len() {
            return false;
        }
        let vert = &self.sim.particles().vert;
        let src = if velocities {
            &vert.v[range]
        } else {
            &vert.x[range]
        };
        for (o, p) in out.chunks_exact_mut(2).zip(src) {
            o[0] = p.x;
            o[1] = p.y;
        }
        true
    }

    pub fn vertices_finite(&self) -> bool {
        let vert = &self.sim.particles().vert;
        vert.x
            .iter()
            .chain(&vert.v)
            .all(|p| p.x.is_finite() && p.y.is_finite())
    }
}
