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

use super::pins::PinMotion;
use super::sim::{Attractor, YarnSim};
use crate::math::{Mat2, Vec2};

/// First bytes of every serialized state.
pub const MAGIC: &[u8; 8] = b"YARNSTAT";
/// Format version.
pub const VERSION: u32 = 2;
const HEADER: usize = 8 + 4 + 8 * 5;

/// Why a byte string is not a state of this simulation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StateError {
    TooShort { len: usize, need: usize },
    BadMagic,
    BadVersion(u32),
    OtherScene,
    CountMismatch { vertices: u64, quads: u64 },
    LengthMismatch { declared: u64, actual: u64 },
    Checksum,
    NonFinite,
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
        }
    }
}

impl std::error::Error for StateError {}

/// 64-bit FNV-1a.
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

    /// The dynamic state as bytes.
    pub fn save_state(&self) -> Vec<u8> {
        let p = self.particles();
        let mut payload = Vec::with_capacity(self.state_size() - HEADER);
        payload.extend_from_slice(&self.time.to_le_bytes());
        payload.extend_from_slice(&self.steps.to_le_bytes());
        put_vec(&mut payload, &self.gravity);
        put_vec(&mut payload, &self.attractor.position);
        payload.extend_from_slice(&self.attractor.strength.to_le_bytes());
        payload.extend_from_slice(&(self.attractor.active as u64).to_le_bytes());
        payload.extend_from_slice(&self.dt.to_le_bytes());
        for k in self.input_pins() {
            if let PinMotion::Input {
                position,
                velocity,
                since,
            } = self.pins()[k].motion
            {
                put_vec(&mut payload, &position);
                put_vec(&mut payload, &velocity);
                payload.extend_from_slice(&since.to_le_bytes());
            }
        }
        for i in 0..p.vert.x.len() {
            put_vec(&mut payload, &p.vert.x[i]);
            put_vec(&mut payload, &p.vert.v[i]);
            put_mat(&mut payload, &p.vert.c[i]);
        }
        for q in 0..p.quad.x.len() {
            put_vec(&mut payload, &p.quad.x[q]);
            put_vec(&mut payload, &p.quad.v[q]);
            put_mat(&mut payload, &p.quad.c[q]);
            put_mat(&mut payload, &p.quad.d[q]);
            put_mat(&mut payload, &p.quad.deformation_gradient(q));
        }
        let mut out = Vec::with_capacity(HEADER + payload.len());
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&self.scene_fingerprint().to_le_bytes());
        out.extend_from_slice(&(p.vert.x.len() as u64).to_le_bytes());
        out.extend_from_slice(&(p.quad.x.len() as u64).to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&fnv1a(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        out
    }

    /// Restores a state written by [`YarnSim::save_state`] for the same
    /// scene. Nothing changes when the bytes are rejected. Restoring clears a
    /// previous divergence.
    pub fn load_state(&mut self, bytes: &[u8]) -> Result<(), StateError> {
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
        for (k, position, velocity, since) in targets {
            self.restore_pin_target(
                k,
                PinMotion::Input {
                    position,
                    velocity,
                    since,
                },
            );
        }
        self.time = time;
        self.steps = steps;
        self.gravity = gravity;
        self.attractor = Attractor {
            position: apos,
            strength: astr,
            active: aact,
        };
        self.dt = dt;
        let p = &mut self.particles;
        (p.vert.x, p.vert.v, p.vert.c) = vert;
        // quad.4 (F) is determined by d; it is stored for readers of the format
        (p.quad.x, p.quad.v, p.quad.c, p.quad.d) = (quad.0, quad.1, quad.2, quad.3);
        self.failed = None;
        self.frames_stale = true;
        Ok(())
    }
}
