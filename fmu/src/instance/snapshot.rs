//! FMU states: the snapshots `fmi2GetFMUstate` hands out (the wrapper's
//! clock and the model's dynamic state, [`FmuModel::save`]; no scratch) and
//! their bytes (`fmi2SerializeFMUstate`): header, checksum, the clock and
//! the model's part, framed by [`crate::models::state_bytes`].

use std::ffi::c_void;

use yarnsim::mpm::driver::state::fnv1a;

use super::phase::Phase;
use crate::instance::clock::Clock;
use crate::models::model::{FmuModel, ModelSnapshot};
use crate::models::state_bytes::{Reader, Writer, STATE_HEADER, STATE_MAGICS, STATE_VERSION};

/// A saved FMU state (`fmi2FMUstate`).
pub struct Snapshot {
    pub(crate) magic: u64,
    pub(crate) phase: Phase,
    pub(crate) clock: Clock,
    /// The model's part ([`FmuModel::save`]).
    pub(crate) physics: ModelSnapshot,
    /// The state magic of the model that made it ([`FmuModel::state_magic`]).
    pub(crate) kind: &'static [u8; 8],
    /// Its number of output objects ([`FmuModel::count`]).
    pub(crate) count: usize,
    /// Serialized form, made on first request.
    pub(crate) bytes: Option<Vec<u8>>,
}

pub(crate) const SNAPSHOT_MAGIC: u64 = 0x5942_534e_4150_5348;

impl Snapshot {
    /// Validates a pointer handed back by the environment.
    ///
    /// # Safety
    /// `p` must be null or a pointer this FMU returned and has not freed.
    pub unsafe fn from_ptr<'a>(p: *mut c_void) -> Option<&'a mut Snapshot> {
        // SAFETY: null, or a live `Snapshot` this FMU handed out (the caller's
        // contract); the magic number below rejects most foreign pointers.
        let s = unsafe { (p as *mut Snapshot).as_mut() }?;
        (s.magic == SNAPSHOT_MAGIC).then_some(s)
    }
}

impl Drop for Snapshot {
    fn drop(&mut self) {
        self.magic = 0;
    }
}

/// The FMU state as bytes: magic (one per model), version, body length,
/// FNV-1a checksum of the body; the body holds the state machine state and
/// the wrapper's time keeping, then the model's part ([`YarnModel::write`],
/// [`MsModel::write`]) of `physics`, a state saved by a model of the kind of
/// `current` (the instance's model). No pointers.
///
/// [`YarnModel::write`]: crate::models::yarn::YarnModel::write
/// [`MsModel::write`]: crate::models::massspring::MsModel::write
pub fn serialize(
    phase: Phase,
    c: &Clock,
    current: &dyn FmuModel,
    physics: &ModelSnapshot,
) -> Result<Vec<u8>, String> {
    // The header goes in front once the body is written.
    let mut w = Writer::with_header(STATE_HEADER);
    w.u8(phase.code());
    w.u8(c.terminated as u8);
    w.u8(c.dirty as u8);
    w.f64(c.start_time);
    w.opt_f64(c.stop_time);
    w.f64(c.time);
    w.f64(c.last_successful_time);
    w.u64(c.substeps);
    current.write(physics, &mut w)?;
    let mut out = w.into_bytes();
    let body = out.len() - STATE_HEADER;
    let sum = fnv1a(&out[STATE_HEADER..]);
    out[..8].copy_from_slice(current.state_magic());
    out[8..12].copy_from_slice(&STATE_VERSION.to_le_bytes());
    out[12..20].copy_from_slice(&(body as u64).to_le_bytes());
    out[20..28].copy_from_slice(&sum.to_le_bytes());
    Ok(out)
}

/// Reads bytes written by [`serialize`] for an FMU of the same model with
/// `count` outputs objects; `current` (with `built`: its simulation matches
/// its scene and parameters) is used to check and decode the model's part
/// when the stored scene and parameters match, else a simulation of the
/// stored scene is built for that.
pub fn deserialize(
    bytes: &[u8],
    current: &dyn FmuModel,
    built: bool,
    count: usize,
) -> Result<(Phase, Clock, ModelSnapshot), String> {
    if bytes.len() < STATE_HEADER {
        return Err(format!(
            "state has {} bytes, at least {STATE_HEADER} needed",
            bytes.len()
        ));
    }
    let magic = current.state_magic();
    if &bytes[..8] != magic {
        let what = if STATE_MAGICS.iter().any(|m| &bytes[..8] == *m) {
            "is the state of the other kind of FMU"
        } else {
            "does not start with a yarnsim FMU state magic"
        };
        return Err(format!(
            "state {what} (expected {:?})",
            String::from_utf8_lossy(&magic[..7])
        ));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if version != STATE_VERSION {
        return Err(format!(
            "state format version {version} is not {STATE_VERSION}"
        ));
    }
    let len = u64::from_le_bytes(bytes[12..20].try_into().unwrap());
    let sum = u64::from_le_bytes(bytes[20..28].try_into().unwrap());
    let body = &bytes[STATE_HEADER..];
    if len != body.len() as u64 {
        return Err(format!(
            "state declares {len} body bytes but has {}",
            body.len()
        ));
    }
    if fnv1a(body) != sum {
        return Err("state checksum does not match: the bytes are corrupt".into());
    }
    let mut r = Reader::new(body);
    let phase = Phase::from_code(r.u8()?).ok_or("bad state machine state")?;
    if matches!(phase, Phase::Error | Phase::Fatal) {
        return Err("state was saved in an error state".into());
    }
    let terminated = r.bool()?;
    let dirty = r.bool()?;
    let clock = Clock {
        dirty,
        start_time: r.f64()?,
        stop_time: r.opt_f64()?,
        time: r.f64()?,
        last_successful_time: r.f64()?,
        substeps: r.u64()?,
        terminated,
    };
    let physics = current.read(&mut r, built, count)?;
    Ok((phase, clock, physics))
}
