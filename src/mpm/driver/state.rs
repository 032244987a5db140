//! Byte serialization of a [`YarnSim`]'s dynamic state.
//!
//! Layout (little endian): the 8-byte magic `YARNSTAT`, a `u32` format
//! version, the `u64` fingerprint of the scene, the vertex and quadrature
//! counts (`u64` each), the payload length (`u64`) and an FNV-1a checksum of
//! the payload (`u64`); then the payload of `f64` values: time, step count,
//! gravity, attractor, substep, the target of every `motion = "input"` pin
//! (position, velocity, reference time), and per particle position,
//! velocity, APIC matrix (and for quadrature particles the frame `d` and
//! `F`). Version 2 added the input pins' targets. No pointers, no padding:
//! a state written by one process reads back in another.

use crate::math::{Mat2, Vec2};
use crate::mpm::driver::{Attractor, YarnSim};
use crate::mpm::laws::pins::PinMotion;

/// First bytes of every serialized state.
pub const MAGIC: &[u8; 8] = b"YARNSTAT";
/// Format version.
pub const VERSION: u32 = 2;
const HEADER: usize = 8 + 4 + 8 * 5;

/// Why a byte string is not a state of this simulation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StateError {
    /// Fewer bytes than the header or the counts need.
    TooShort {
        /// Bytes given.
        len: usize,
        /// Bytes needed.
        need: usize,
    },
    /// Not a yarn state (wrong magic number).
    BadMagic,
    /// A state of another format version.
    BadVersion(u32),
    /// A state of another scene (its fingerprint differs).
    OtherScene,
    /// Particle counts other than the scene's.
    CountMismatch {
        /// Vertices stored.
        vertices: u64,
        /// Quadrature particles stored.
        quads: u64,
    },
    /// The stored length disagrees with the bytes given.
    LengthMismatch {
        /// Payload length the header declares.
        declared: u64,
        /// Payload length given.
        actual: u64,
    },
    /// The checksum does not match the bytes.
    Checksum,
    /// A stored value is NaN or infinite.
    NonFinite,
    /// A stored input (gravity, attractor) outside the limits the
    /// simulation accepts from its setters.
    BadInput(String),
}

impl std::fmt::Display for StateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StateError::TooShort { len, need } => {
                write!(f, "state has {len} bytes, at least {need} needed")
            }
            StateError::BadMagic => write!(f, "state does not start with the YARNSTAT magic"),
            StateError::BadVersion(v) => write!(f, "state format version {v} is not {VERSION}"),
            StateError::OtherScene => write!(f, "state was saved from a different scene"),
            StateError::CountMismatch { vertices, quads } => {
                write!(f, "state holds {vertices} vertices and {quads} quadrature particles, the scene has others")
            }
            StateError::LengthMismatch { declared, actual } => {
                write!(
                    f,
                    "state payload declares {declared} bytes but has {actual}"
                )
            }
            StateError::Checksum => {
                write!(f, "state checksum does not match: the bytes are corrupt")
            }
            StateError::NonFinite => write!(f, "state contains non-finite numbers"),
            StateError::BadInput(m) => write!(f, "state holds a refused input: {m}"),
        }
    }
}

impl std::error::Error for StateError {}

/// 64-bit FNV-1a (Fowler, Noll, Vo): the checksum of the saved state's
/// payload, and so part of the state format, not a test helper. Public
/// because the FMU's state bytes carry the same checksum and its GUID is
/// derived with it.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf29ce484222325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x100000001b3);
    }
    h
}

fn put_vec(out: &mut Vec<u8>, v: &Vec2) {
    out.extend_from_slice(&v.x.to_le_bytes());
    out.extend_from_slice(&v.y.to_le_bytes());
}

fn put_mat(out: &mut Vec<u8>, m: &Mat2) {
    for e in m.iter() {
        out.extend_from_slice(&e.to_le_bytes());
    }
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn f64(&mut self) -> f64 {
        let v = f64::from_le_bytes(self.b[self.at..self.at + 8].try_into().unwrap());
        self.at += 8;
        v
    }
    fn u64(&mut self) -> u64 {
        let v = u64::from_le_bytes(self.b[self.at..self.at + 8].try_into().unwrap());
        self.at += 8;
        v
    }
    fn vec(&mut self) -> Vec2 {
        Vec2::new(self.f64(), self.f64())
    }
    fn mat(&mut self) -> Mat2 {
        let mut m = Mat2::zeros();
        for e in m.iter_mut() {
            *e = self.f64();
        }
        m
    }
}

/// Everything that determines a [`YarnSim`]'s future (bit for bit): the
/// clock, the inputs (gravity, attractor, the targets of the input pins) and
/// per particle position, velocity, APIC matrix and, for the quadrature
/// particles, the frame `d`. No grid and no other scratch: what
/// [`YarnSim::dynamic_state`] copies, [`YarnSim::set_dynamic_state`] puts
/// back and [`YarnSim::save_state`] writes (through
/// [`YarnSim::encode_state`]).
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicState {
    time: f64,
    steps: u64,
    gravity: Vec2,
    attractor: Attractor,
    dt: f64,
    /// Per input pin: its index, target position, velocity, reference time.
    targets: Vec<(usize, Vec2, Vec2, f64)>,
    vert_x: Vec<Vec2>,
    vert_v: Vec<Vec2>,
    vert_c: Vec<Mat2>,
    quad_x: Vec<Vec2>,
    quad_v: Vec<Vec2>,
    quad_c: Vec<Mat2>,
    quad_d: Vec<Mat2>,
}

impl DynamicState {
    /// Simulated time in s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Substeps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
}

impl YarnSim {
    /// Fingerprint of the scene, stored in serialized states.
    pub fn scene_fingerprint(&self) -> u64 {
        fnv1a(self.scene().to_toml_string().as_bytes())
    }

    /// Size in bytes of [`YarnSim::save_state`]'s output.
    pub fn state_size(&self) -> usize {
        let p = self.particles();
        HEADER
            + 8 * (2 + 2 + 2 + 2 + 1)
            + self.input_pins().count() * 8 * 5
            + p.vert.x.len() * 8 * 8
            + p.quad.x.len() * 8 * 16
    }

    /// Index of every `motion = "input"` pin.
    fn input_pins(&self) -> impl Iterator<Item = usize> + '_ {
        self.pins()
            .iter()
            .enumerate()
            .filter(|(_, p)| matches!(p.motion, PinMotion::Input { .. }))
            .map(|(i, _)| i)
    }

    /// A copy of the dynamic state (no grid, no scratch).
    pub fn dynamic_state(&self) -> DynamicState {
        let p = self.particles();
        DynamicState {
            time: self.time,
            steps: self.steps,
            gravity: self.gravity,
            attractor: self.attractor,
            dt: self.dt,
            targets: self
                .input_pins()
                .filter_map(|k| match self.pins()[k].motion {
                    PinMotion::Input {
                        position,
                        velocity,
                        since,
                    } => Some((k, position, velocity, since)),
                    _ => None,
                })
                .collect(),
            vert_x: p.vert.x.clone(),
            vert_v: p.vert.v.clone(),
            vert_c: p.vert.c.clone(),
            quad_x: p.quad.x.clone(),
            quad_v: p.quad.v.clone(),
            quad_c: p.quad.c.clone(),
            quad_d: p.quad.d.clone(),
        }
    }

    /// Fails unless `s` has this simulation's particle counts and input pins.
    fn check_fits(&self, s: &DynamicState) -> Result<(), StateError> {
        let p = self.particles();
        let (nv, nq) = (p.vert.x.len(), p.quad.x.len());
        let sizes = [&s.vert_x, &s.vert_v, &s.quad_x, &s.quad_v]
            .map(|v| v.len())
            .into_iter()
            .zip([nv, nv, nq, nq])
            .chain(
                [&s.vert_c, &s.quad_c, &s.quad_d]
                    .map(|v| v.len())
                    .into_iter()
                    .zip([nv, nq, nq]),
            )
            .all(|(a, b)| a == b);
        if !sizes {
            return Err(StateError::CountMismatch {
                vertices: s.vert_x.len() as u64,
                quads: s.quad_x.len() as u64,
            });
        }
        if !s.targets.iter().map(|t| t.0).eq(self.input_pins()) {
            return Err(StateError::OtherScene);
        }
        Ok(())
    }

    /// Puts back a [`YarnSim::dynamic_state`] of a simulation of the same
    /// scene (the arrays are copied into the existing ones). Nothing changes
    /// when it does not fit (other particle counts or input pins). Restoring
    /// clears a previous divergence.
    pub fn set_dynamic_state(&mut self, s: &DynamicState) -> Result<(), StateError> {
        self.check_fits(s)?;
        for &(k, position, velocity, since) in &s.targets {
            self.restore_pin_target(
                k,
                PinMotion::Input {
                    position,
                    velocity,
                    since,
                },
            );
        }
        self.time = s.time;
        self.steps = s.steps;
        self.gravity = s.gravity;
        self.attractor = s.attractor;
        self.dt = s.dt;
        let p = &mut self.particles;
        p.vert.x.clone_from(&s.vert_x);
        p.vert.v.clone_from(&s.vert_v);
        p.vert.c.clone_from(&s.vert_c);
        p.quad.x.clone_from(&s.quad_x);
        p.quad.v.clone_from(&s.quad_v);
        p.quad.c.clone_from(&s.quad_c);
        p.quad.d.clone_from(&s.quad_d);
        self.failed = None;
        self.frames_stale = true;
        Ok(())
    }

    /// The dynamic state as bytes.
    pub fn save_state(&self) -> Vec<u8> {
        self.encode_state(&self.dynamic_state())
            .expect("a simulation's own state fits it")
    }

    /// A dynamic state of a simulation of this scene as bytes (the format
    /// of [`YarnSim::save_state`]; this simulation gives the scene
    /// fingerprint and the rest frames for the stored `F`).
    pub fn encode_state(&self, s: &DynamicState) -> Result<Vec<u8>, StateError> {
        let mut out = Vec::with_capacity(self.state_size());
        self.encode_state_into(s, &mut out)?;
        Ok(out)
    }

    /// [`YarnSim::encode_state`], appended to `out` ([`YarnSim::state_size`]
    /// bytes).
    pub fn encode_state_into(&self, s: &DynamicState, out: &mut Vec<u8>) -> Result<(), StateError> {
        self.check_fits(s)?;
        let rest_inv = &self.particles().quad.d_rest_inv;
        let (nv, nq) = (s.vert_x.len(), s.quad_x.len());
        let start = out.len();
        let len = self.state_size() - HEADER;
        out.reserve(HEADER + len);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&self.scene_fingerprint().to_le_bytes());
        out.extend_from_slice(&(nv as u64).to_le_bytes());
        out.extend_from_slice(&(nq as u64).to_le_bytes());
        out.extend_from_slice(&(len as u64).to_le_bytes());
        out.extend_from_slice(&0u64.to_le_bytes()); // the checksum, below
        out.extend_from_slice(&s.time.to_le_bytes());
        out.extend_from_slice(&s.steps.to_le_bytes());
        put_vec(out, &s.gravity);
        put_vec(out, &s.attractor.position);
        out.extend_from_slice(&s.attractor.strength.to_le_bytes());
        out.extend_from_slice(&(s.attractor.active as u64).to_le_bytes());
        out.extend_from_slice(&s.dt.to_le_bytes());
        for (_, position, velocity, since) in &s.targets {
            put_vec(out, position);
            put_vec(out, velocity);
            out.extend_from_slice(&since.to_le_bytes());
        }
        for ((x, v), c) in s.vert_x.iter().zip(&s.vert_v).zip(&s.vert_c) {
            put_vec(out, x);
            put_vec(out, v);
            put_mat(out, c);
        }
        let quads = s.quad_x.iter().zip(&s.quad_v).zip(&s.quad_c).zip(&s.quad_d);
        for ((((x, v), c), d), rest_inv) in quads.zip(rest_inv) {
            put_vec(out, x);
            put_vec(out, v);
            put_mat(out, c);
            put_mat(out, d);
            // F = d D^-1 (Quads::deformation_gradient), for readers of the format.
            put_mat(out, &(d * rest_inv));
        }
        debug_assert_eq!(out.len() - start, HEADER + len);
        let sum = fnv1a(&out[start + HEADER..]);
        out[start + HEADER - 8..start + HEADER].copy_from_slice(&sum.to_le_bytes());
        Ok(())
    }

    /// Restores a state written by [`YarnSim::save_state`] for the same
    /// scene. Nothing changes when the bytes are rejected. Restoring clears a
    /// previous divergence.
    pub fn load_state(&mut self, bytes: &[u8]) -> Result<(), StateError> {
        let s = self.decode_state(bytes)?;
        self.set_dynamic_state(&s)
    }

    /// Reads and checks bytes written by [`YarnSim::save_state`] for this
    /// scene, without changing the simulation.
    pub fn decode_state(&self, bytes: &[u8]) -> Result<DynamicState, StateError> {
        if bytes.len() < HEADER {
            return Err(StateError::TooShort {
                len: bytes.len(),
                need: HEADER,
            });
        }
        if &bytes[..8] != MAGIC {
            return Err(StateError::BadMagic);
        }
        let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
        if version != VERSION {
            return Err(StateError::BadVersion(version));
        }
        let mut r = Reader { b: bytes, at: 12 };
        let fp = r.u64();
        let (nv, nq) = (r.u64(), r.u64());
        let declared = r.u64();
        let checksum = r.u64();
        if fp != self.scene_fingerprint() {
            return Err(StateError::OtherScene);
        }
        let p = self.particles();
        if nv != p.vert.x.len() as u64 || nq != p.quad.x.len() as u64 {
            return Err(StateError::CountMismatch {
                vertices: nv,
                quads: nq,
            });
        }
        let actual = (bytes.len() - HEADER) as u64;
        if declared != actual || bytes.len() != self.state_size() {
            return Err(StateError::LengthMismatch { declared, actual });
        }
        if fnv1a(&bytes[HEADER..]) != checksum {
            return Err(StateError::Checksum);
        }
        // Decode into copies first so a bad value leaves the state untouched.
        let time = r.f64();
        let steps = r.u64();
        let gravity = r.vec();
        let apos = r.vec();
        let astr = r.f64();
        let aact = r.u64() != 0;
        let dt = r.f64();
        let targets: Vec<(usize, Vec2, Vec2, f64)> = self
            .input_pins()
            .collect::<Vec<_>>()
            .into_iter()
            .map(|k| (k, r.vec(), r.vec(), r.f64()))
            .collect();
        let mut vert = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..nv {
            vert.0.push(r.vec());
            vert.1.push(r.vec());
            vert.2.push(r.mat());
        }
        let mut quad = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for _ in 0..nq {
            quad.0.push(r.vec());
            quad.1.push(r.vec());
            quad.2.push(r.mat());
            quad.3.push(r.mat());
            quad.4.push(r.mat());
        }
        let finite = [time, gravity.x, gravity.y, apos.x, apos.y, astr, dt]
            .iter()
            .all(|v| v.is_finite())
            && vert
                .0
                .iter()
                .chain(&vert.1)
                .chain(&quad.0)
                .chain(&quad.1)
                .all(|v| v.x.is_finite() && v.y.is_finite())
            && vert
                .2
                .iter()
                .chain(&quad.2)
                .chain(&quad.3)
                .chain(&quad.4)
                .all(|m| m.iter().all(|e| e.is_finite()));
        let finite = finite
            && targets.iter().all(|(_, x, v, s)| {
                [x.x, x.y, v.x, v.y, *s].iter().all(|e| e.is_finite())
                    && x.norm() <= 1e6
                    && v.norm() <= 1e6
            });
        if !finite || dt <= 0.0 {
            return Err(StateError::NonFinite);
        }
        let attractor = Attractor {
            position: apos,
            strength: astr,
            active: aact,
        };
        // The inputs' limits are the setters' (one check for each input).
        YarnSim::check_gravity(gravity)
            .and_then(|_| attractor.check())
            .map_err(|e| StateError::BadInput(e.to_string()))?;
        // quad.4 (F) is determined by d; it is stored for readers of the format
        Ok(DynamicState {
            time,
            steps,
            gravity,
            attractor,
            dt,
            targets,
            vert_x: vert.0,
            vert_v: vert.1,
            vert_c: vert.2,
            quad_x: quad.0,
            quad_v: quad.1,
            quad_c: quad.2,
            quad_d: quad.3,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{builtin, Scene};

    fn small_sim() -> YarnSim {
        let Some(Scene::Yarn(scene)) = builtin("yarn-drape") else {
            unreachable!()
        };
        YarnSim::new(&scene).unwrap()
    }

    /// A stored gravity or attractor beyond the setters' limits is refused
    /// on decoding, by the same checks as the setters (finite, 1e6).
    #[test]
    fn stored_inputs_beyond_the_setters_limits_are_refused() {
        let sim = small_sim();
        let good = sim.dynamic_state();
        assert!(sim.decode_state(&sim.encode_state(&good).unwrap()).is_ok());
        let mut far = good.clone();
        far.attractor.position.x = 2e6;
        let mut strong = good.clone();
        strong.attractor.strength = -1.0;
        let mut heavy = good.clone();
        heavy.gravity.y = -2e6;
        for (what, s) in [
            ("attractor", far),
            ("attractor", strong),
            ("gravity", heavy),
        ] {
            let bytes = sim.encode_state(&s).unwrap();
            match sim.decode_state(&bytes) {
                Err(StateError::BadInput(m)) => assert!(m.contains(what), "{m}"),
                other => panic!("{what}: {other:?}"),
            }
        }
    }
}
