//! The instance's FMU states (the one meaning of "state" in this crate):
//! get, set, serialize and deserialize.

use super::*;

impl Instance {
    /// Saves the clock and the model's part ([`FmuModel::save`]: its
    /// values, no scratch such as the MPM grid), into `into` or a new
    /// snapshot.
    pub fn get_fmu_state(&mut self, into: Option<&mut Snapshot>) -> Res<Option<Box<Snapshot>>> {
        self.require(Operation::GetFmuState)?;
        // A snapshot always holds the state of a simulation built from its
        // parameters.
        self.model.ensure_built(self.count)?;
        let physics = self.model.physics.save();
        match into {
            Some(s) => {
                s.phase = self.phase;
                s.clock = self.model.clock();
                s.physics = physics;
                s.kind = self.model.physics.state_magic();
                s.count = self.count;
                s.bytes = None;
                Ok(None)
            }
            None => Ok(Some(Box::new(Snapshot {
                magic: SNAPSHOT_MAGIC,
                phase: self.phase,
                clock: self.model.clock(),
                physics,
                kind: self.model.physics.state_magic(),
                count: self.count,
                bytes: None,
            }))),
        }
    }

    /// Puts a snapshot back: the model reuses its simulation (and its
    /// scratch) when the snapshot's scene and parameters are those it was
    /// built from, else builds one of them first.
    pub fn set_fmu_state(&mut self, s: &Snapshot) -> Res {
        self.require(Operation::SetFmuState)?;
        if s.kind != self.model.physics.state_magic() || s.count != self.count {
            return error(format!(
                "{}: the state belongs to another FMU (other model or number of outputs)",
                self.op_name(Operation::SetFmuState)
            ));
        }
        self.model
            .physics
            .load(&s.physics)
            .or_else(|e| error(format!("{}: {e}", self.op_name(Operation::SetFmuState))))?;
        self.model.set_clock(&s.clock);
        self.phase = s.phase;
        self.log(
            Status::Ok,
            LOG_EVENTS,
            &format!("state restored: t = {}", self.model.clock.time),
        );
        Ok(())
    }

    /// The serialized bytes of a snapshot (made once, then cached).
    /// `op`: [`Operation::SerializedFmuStateSize`] or
    /// [`Operation::SerializeFmuState`], the function its messages name.
    pub fn serialize<'a>(&self, op: Operation, s: &'a mut Snapshot) -> Res<&'a [u8]> {
        self.require(op)?;
        let func = self.op_name(op);
        if s.bytes.is_none() {
            if s.kind != self.model.physics.state_magic() || s.count != self.count {
                return error(format!(
                    "{func}: the state belongs to another FMU (other model or number of outputs)"
                ));
            }
            let bytes = serialize(s.phase, &s.clock, self.model.physics.as_ref(), &s.physics)
                .or_else(|e| error(format!("{func}: {e}")))?;
            s.bytes = Some(bytes);
        }
        Ok(s.bytes.as_deref().unwrap())
    }

    pub fn deserialize(&mut self, bytes: &[u8]) -> Res<Box<Snapshot>> {
        self.require(Operation::DeserializeFmuState)?;
        let m = &self.model;
        let (phase, clock, physics) =
            deserialize(bytes, m.physics.as_ref(), !m.clock.dirty, self.count).or_else(|e| {
                let func = self.op_name(Operation::DeserializeFmuState);
                error(format!("{func}: {e}"))
            })?;
        Ok(Box::new(Snapshot {
            magic: SNAPSHOT_MAGIC,
            phase,
            clock,
            physics,
            kind: m.physics.state_magic(),
            count: self.count,
            bytes: Some(bytes.to_vec()),
        }))
    }
}
