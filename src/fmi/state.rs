//! The FMU state: the part of an instance a host saves and restores
//! ([`Saved`]), its bytes (a magic line, the instantiation token, then
//! postcard) and their checks, and the operations on a state that both
//! standards' exported functions call.

use super::fmu::Fmu;
use super::instance::{
    ANY_STATE, INITIALIZATION_MODE, INSTANTIATED, Instance, STEP_DISCARDED, STEP_MODE, Status,
    call, experiment_error, mask, with_instance,
};
use super::log::CAT_EVENTS;
use crate::ffi::{slice, slice_mut};
use crate::{Scene, Simulation};
use std::ffi::{c_int, c_void};

/// The part of an instance that a host saves and restores (FMU state).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Saved {
    state: u32,
    scene: Scene,
    sim: Option<Simulation>,
    start_time: f64,
    /// The experiment's stopTime goes with its startTime: a host that
    /// restores a state after Reset, or in another instance, gets the
    /// experiment the run belongs to. (Absent in bytes from before: none.)
    #[serde(default)]
    stop_time: Option<f64>,
    time: f64,
    at_end: bool,
    last_successful_time: f64,
}

/// The first line of a serialized state, after the model identifier: the
/// version of its encoding. Version 2 is postcard; version 1 (JSON) is
/// refused with a message saying so.
const STATE_MAGIC: &[u8] = b" FMU state v2 postcard\n";

/// The first line of a version 1 (JSON) state, after the model identifier.
const STATE_MAGIC_V1: &[u8] = b" FMU state v1\n";

impl Fmu {
    /// A serialized state of this FMU (`fmi3SerializeFMUState`,
    /// `fmi2SerializeFMUstate`) as JSON, to read it, or to forge one in a
    /// test: decoded field by field, not checked. An error says why the
    /// bytes are not a state of this version of the FMU.
    pub fn state_to_json(self, bytes: &[u8]) -> Result<serde_json::Value, String> {
        let saved = Saved::decode(self, bytes)?;
        serde_json::to_value(&saved).map_err(|e| format!("the state as JSON: {e}"))
    }

    /// Serialized state bytes of this FMU from JSON of the shape
    /// [`Fmu::state_to_json`] gives, encoded as the FMU encodes them but not
    /// checked: `fmi3DeserializeFMUState` checks them. An error says which
    /// part does not have the type of its field.
    pub fn state_from_json(self, json: serde_json::Value) -> Result<Vec<u8>, String> {
        let saved: Saved =
            serde_json::from_value(json).map_err(|e| format!("not an FMU state: {e}"))?;
        Ok(saved.serialize(self))
    }
}

impl Instance {
    pub(crate) fn save(&self) -> Saved {
        Saved {
            state: self.state,
            scene: self.scene.clone(),
            sim: self.sim.clone(),
            start_time: self.start_time,
            stop_time: self.stop_time,
            time: self.time,
            at_end: self.at_end,
            last_successful_time: self.last_successful_time,
        }
    }

    pub(crate) fn restore(&mut self, s: &Saved) {
        self.state = s.state;
        self.scene = s.scene.clone();
        self.sim = s.sim.clone();
        self.start_time = s.start_time;
        self.stop_time = s.stop_time;
        self.time = s.time;
        self.at_end = s.at_end;
        self.last_successful_time = s.last_successful_time;
        self.log(
            Status::Ok,
            CAT_EVENTS,
            &format!("FMU state restored at t = {} s", self.time),
        );
    }
}

/// The first two lines of a serialized state of `fmu`: the model
/// identifier and [`STATE_MAGIC`], then the instantiation token.
fn state_header(fmu: Fmu) -> Vec<u8> {
    let mut out = fmu.identity().model_identifier.as_bytes().to_vec();
    out.extend_from_slice(STATE_MAGIC);
    out.extend_from_slice(fmu.token().as_bytes());
    out.push(b'\n');
    out
}

impl Saved {
    /// Bytes of this state of an instance of `fmu`: a magic line (the model
    /// identifier and the version of the encoding), the instantiation
    /// token, then the state in postcard (8 bytes per double, lengths and
    /// counts as varints; the same fields as [`Fmu::state_to_json`] shows).
    pub(crate) fn serialize(&self, fmu: Fmu) -> Vec<u8> {
        let mut out = state_header(fmu);
        postcard::to_io(self, &mut out).expect("a state encodes into a vector");
        out
    }

    /// The length of [`Saved::serialize`]'s bytes, counted without making
    /// them.
    pub(crate) fn serialized_len(&self, fmu: Fmu) -> usize {
        state_header(fmu).len() + crate::model::postcard_len(self)
    }

    /// Writes [`Saved::serialize`]'s bytes into `out` (a host's buffer),
    /// or says why not if it is not exactly their length.
    pub(crate) fn serialize_into(&self, fmu: Fmu, out: &mut [u8]) -> Result<(), String> {
        let len = self.serialized_len(fmu);
        if out.len() != len {
            return Err(format!(
                "size = {} but the serialized state has {len} bytes",
                out.len()
            ));
        }
        let header = state_header(fmu);
        let (head, body) = out.split_at_mut(header.len());
        head.copy_from_slice(&header);
        postcard::to_slice(self, body).expect("the length counted above");
        Ok(())
    }

    /// The state in [`Saved::serialize`] bytes of an instance of `fmu`,
    /// decoded but not checked: a message for the log if the bytes are not
    /// such a state of this version of `fmu`.
    fn decode(fmu: Fmu, bytes: &[u8]) -> Result<Saved, String> {
        let id = fmu.identity().model_identifier;
        let after_id = bytes.strip_prefix(id.as_bytes());
        if after_id.is_some_and(|r| r.starts_with(STATE_MAGIC_V1)) {
            return Err(format!(
                "the bytes are a version 1 (JSON) {id} FMU state of an older build; this one reads version 2 (postcard)"
            ));
        }
        let rest = after_id
            .and_then(|r| r.strip_prefix(STATE_MAGIC))
            .ok_or_else(|| format!("the bytes are not a serialized {id} FMU state"))?;
        let rest = rest
            .strip_prefix(fmu.token().as_bytes())
            .and_then(|r| r.strip_prefix(b"\n"))
            .ok_or("the serialized state comes from a different version of the FMU")?;
        let (saved, left) = postcard::take_from_bytes::<Saved>(rest)
            .map_err(|e| format!("invalid serialized state: {e}"))?;
        if !left.is_empty() {
            return Err(format!(
                "invalid serialized state: {} bytes follow its end",
                left.len()
            ));
        }
        Ok(saved)
    }

    /// Parses [`Saved::serialize`] bytes of an instance of `fmu`, and checks
    /// the state as a new instance's values and run are checked.
    pub(crate) fn deserialize(fmu: Fmu, bytes: &[u8]) -> Result<Saved, String> {
        let saved = Saved::decode(fmu, bytes)?;
        if saved.state & ANY_STATE == 0 || saved.state.count_ones() != 1 {
            return Err("invalid serialized state: unknown instance state".into());
        }
        // Checked as a new instance's values and run are: a forged state is
        // refused here, not found out by a later step.
        saved
            .scene
            .validate()
            .map_err(|e| format!("invalid serialized state: its parameters: {e}"))?;
        let times = [saved.start_time, saved.time, saved.last_successful_time];
        if !times.iter().all(|t| t.is_finite()) || saved.time < saved.start_time {
            return Err("invalid serialized state: its communication times are not valid".into());
        }
        if let Some(e) = experiment_error(saved.start_time, saved.stop_time) {
            return Err(format!("invalid serialized state: its experiment: {e}"));
        }
        if saved.scene.kind() != fmu.kind() {
            return Err(format!(
                "invalid serialized state: its parameters are not the `{}` scene's",
                fmu.kind().name()
            ));
        }
        // An FMU's scene keeps the reference values of its kind (no
        // variable sets them): anything else, a NaN say, is forged.
        if saved.scene.reference != Scene::default_of(fmu.kind()).reference {
            return Err(
                "invalid serialized state: its reference values are not the scene's".into(),
            );
        }
        // The run is there exactly when an instance in that state has one,
        // and it is the run of the instance's parameters (those it reports).
        let run = match (&saved.sim, saved.state) {
            (None, STEP_MODE | STEP_DISCARDED) => Err("it is past initialization but holds no run"),
            (Some(_), INSTANTIATED) => Err("it holds a run before initialization"),
            (Some(sim), _) if sim.scene() != &saved.scene => {
                Err("its run is not one of its parameters")
            }
            (Some(sim), INITIALIZATION_MODE) if sim.steps() != 0 => {
                Err("its run has stepped before the end of initialization")
            }
            _ => Ok(()),
        };
        run.map_err(|e| format!("invalid serialized state: {e}"))?;
        if let Some(sim) = &saved.sim {
            sim.check_restored()
                .map_err(|e| format!("invalid serialized state: {e}"))?;
        }
        Ok(saved)
    }
}

/// Puts `saved` where the host's `*state` points: a new state when
/// `*state` is NULL, else in place of the state there.
///
/// # Safety
/// `state` writable and not NULL; a non-null `*state` a state this FMU
/// handed out and has not freed.
unsafe fn hand_out(state: *mut *mut c_void, saved: Saved) {
    // SAFETY: by the contract, `state` is writable and a non-null `*state`
    // is a live `Box<Saved>`.
    unsafe {
        if (*state).is_null() {
            *state = Box::into_raw(Box::new(saved)) as *mut c_void;
        } else {
            *(*state as *mut Saved) = saved;
        }
    }
}

/// `fmi3GetFMUState` / `fmi2GetFMUstate`: a copy of the instance's state
/// (a new one, or overwriting `*state` when it is not NULL).
///
/// # Safety
/// `state` writable; `*state` NULL or a state of this FMU.
pub(crate) unsafe fn get_fmu_state(
    instance: *mut c_void,
    function: &str,
    state: *mut *mut c_void,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe {
        call(instance, function, mask::FMU_STATE, |inst| {
            if state.is_null() {
                return inst.fail(&format!("{function}: FMUState is NULL"));
            }
            if let Some(Err(e)) = inst.sim.as_ref().map(|s| s.check_savable()) {
                return inst.fail(&format!("{function}: the run has no state to save: {e}"));
            }
            hand_out(state, inst.save());
            Status::Ok
        })
    }
}

/// `fmi3SetFMUState` / `fmi2SetFMUstate`: restores a state.
///
/// # Safety
/// `state` NULL or a live state of this FMU.
pub(crate) unsafe fn set_fmu_state(
    instance: *mut c_void,
    function: &str,
    state: *mut c_void,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe {
        call(instance, function, mask::FMU_STATE, |inst| {
            if state.is_null() {
                return inst.fail(&format!("{function}: FMUState is NULL"));
            }
            // SAFETY: a live `Box<Saved>` of this FMU by the contract.
            let saved = &*(state as *const Saved);
            inst.restore(saved);
            Status::Ok
        })
    }
}

/// `fmi3FreeFMUState` / `fmi2FreeFMUstate`: frees `*state` and sets it to
/// NULL.
///
/// # Safety
/// `state` NULL or writable; `*state` NULL or a live state of this FMU.
pub(crate) unsafe fn free_fmu_state(instance: *mut c_void, state: *mut *mut c_void) -> c_int {
    // SAFETY: forwarded contract.
    (unsafe {
        with_instance(instance, |_inst| {
            if !state.is_null() && !(*state).is_null() {
                // SAFETY: a `Box<Saved>` from `get_fmu_state`, freed once.
                drop(Box::from_raw(*state as *mut Saved));
                *state = std::ptr::null_mut();
            }
            Status::Ok
        })
    }) as c_int
}

/// `fmi3SerializedFMUStateSize` / `fmi2SerializedFMUstateSize`.
///
/// # Safety
/// `state` a live state of this FMU; `size` writable.
pub(crate) unsafe fn serialized_size(
    instance: *mut c_void,
    function: &str,
    state: *mut c_void,
    size: *mut usize,
) -> c_int {
    // SAFETY: forwarded contract.
    (unsafe {
        with_instance(instance, |inst| {
            if state.is_null() || size.is_null() {
                return inst.fail(&format!("{function}: FMUState or size is NULL"));
            }
            // SAFETY: a live `Box<Saved>`; `size` writable.
            *size = (*(state as *const Saved)).serialized_len(inst.fmu);
            Status::Ok
        })
    }) as c_int
}

/// `fmi3SerializeFMUState` / `fmi2SerializeFMUstate`.
///
/// # Safety
/// `state` a live state; `bytes` has room for `size` bytes.
pub(crate) unsafe fn serialize(
    instance: *mut c_void,
    function: &str,
    state: *mut c_void,
    bytes: *mut u8,
    size: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    (unsafe {
        with_instance(instance, |inst| {
            if state.is_null() {
                return inst.fail(&format!("{function}: FMUState is NULL"));
            }
            // SAFETY: a live `Box<Saved>`.
            let saved = &*(state as *const Saved);
            let Some(out) = slice_mut(bytes, size) else {
                return inst.fail(&format!("{function}: serializedState is NULL"));
            };
            match saved.serialize_into(inst.fmu, out) {
                Ok(()) => Status::Ok,
                Err(e) => inst.fail(&format!("{function}: {e}")),
            }
        })
    }) as c_int
}

/// `fmi3DeserializeFMUState` / `fmi2DeSerializeFMUstate`: a state from
/// bytes of `Saved::serialize`, checked.
///
/// # Safety
/// `bytes` holds `size` bytes; `state` writable.
pub(crate) unsafe fn deserialize(
    instance: *mut c_void,
    function: &str,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> c_int {
    // SAFETY: forwarded contract.
    (unsafe {
        with_instance(instance, |inst| {
            let Some(data) = slice(bytes, size) else {
                return inst.fail(&format!("{function}: serializedState is NULL"));
            };
            if state.is_null() {
                return inst.fail(&format!("{function}: FMUState is NULL"));
            }
            match Saved::deserialize(inst.fmu, data) {
                Ok(saved) => {
                    hand_out(state, saved);
                    Status::Ok
                }
                Err(e) => inst.fail(&format!("{function}: {e}")),
            }
        })
    }) as c_int
}

#[cfg(test)]
mod tests {
    use super::super::instance::{Standard, TERMINATED};
    use super::super::log::LogSink;
    use super::super::{coarse, taylor_fmu, vr_in};
    use super::*;
    use crate::fmi::fmu::VarType;

    /// Serialized state bytes decoded to the typed state, edited by `edit`
    /// in its JSON form, and encoded again (unchecked).
    fn forge(bytes: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
        let mut json = taylor_fmu().state_to_json(bytes).unwrap();
        edit(&mut json);
        taylor_fmu().state_from_json(json).unwrap()
    }

    /// Found by the FMU call-order fuzzer: a state in step mode without its
    /// run was accepted, and the next doStep panicked (Fatal). A run and
    /// parameters that do not belong together are refused as well: the
    /// outputs would not be those of the parameters, and a Noh run or scene
    /// has none of the Taylor variables.
    #[test]
    fn states_whose_run_does_not_fit_are_refused() {
        let mut inst = coarse(Standard::Fmi3);
        inst.enter_initialization_mode();
        let init = inst.save().serialize(taylor_fmu());
        inst.exit_initialization_mode();
        inst.do_step("doStep", 0.0, 1e-6).unwrap();
        let stepped = inst.save().serialize(taylor_fmu());
        let mut other = Scene::builtin("taylor").unwrap();
        other.set("particles_radial", 5.0).unwrap();
        let other = serde_json::to_value(Simulation::new(other).unwrap()).unwrap();
        let mut noh = Scene::builtin("noh").unwrap();
        noh.set("particles_radial", 100.0).unwrap();
        let noh = serde_json::to_value(Simulation::new(noh).unwrap()).unwrap();
        let refused = |bytes: &[u8], why: &str| {
            let e = Saved::deserialize(taylor_fmu(), bytes).unwrap_err();
            assert!(e.contains(why), "{e} should say {why}");
        };
        refused(
            &forge(&stepped, |j| j["sim"] = serde_json::Value::Null),
            "holds no run",
        );
        let mut done = forge(&stepped, |j| j["sim"] = serde_json::Value::Null);
        done = forge(&done, |j| j["state"] = serde_json::json!(STEP_DISCARDED));
        refused(&done, "holds no run");
        refused(
            &forge(&stepped, |j| j["state"] = serde_json::json!(INSTANTIATED)),
            "before initialization",
        );
        refused(
            &forge(&stepped, |j| {
                j["state"] = serde_json::json!(INITIALIZATION_MODE)
            }),
            "stepped",
        );
        refused(
            &forge(&stepped, |j| j["sim"] = other.clone()),
            "not one of its parameters",
        );
        refused(
            &forge(&stepped, |j| j["sim"] = noh.clone()),
            "not one of its parameters",
        );
        refused(
            &forge(&init, |j| j["scene"] = noh["scene"].clone()),
            "not the `taylor` scene's",
        );
        // The honest states load, and one without a run where that is right.
        assert!(Saved::deserialize(taylor_fmu(), &stepped).is_ok());
        assert!(Saved::deserialize(taylor_fmu(), &init).is_ok());
        let ended = forge(&stepped, |j| {
            j["sim"] = serde_json::Value::Null;
            j["state"] = serde_json::json!(TERMINATED);
        });
        assert!(Saved::deserialize(taylor_fmu(), &ended).is_ok());
    }

    /// Found by the FMU call-order fuzzer: the stopTime was not part of the
    /// FMU state, so a state restored after Reset (or deserialized into a
    /// new instance) stepped past the stopTime of its experiment.
    #[test]
    fn the_stop_time_is_part_of_the_state() {
        let mut inst = coarse(Standard::Fmi3);
        assert_eq!(inst.set_experiment("f", 0.0, Some(2e-6)), Status::Ok);
        inst.enter_initialization_mode();
        inst.exit_initialization_mode();
        inst.do_step("doStep", 0.0, 1e-6).unwrap();
        let saved = inst.save();
        let bytes = saved.serialize(taylor_fmu());
        inst.reset();
        assert_eq!(inst.stop_time, None);
        inst.restore(&saved);
        assert_eq!(inst.stop_time, Some(2e-6));
        assert_eq!(
            inst.do_step("doStep", 1e-6, 2e-6).unwrap_err(),
            Status::Error
        );
        let mut other = Instance::new(Standard::Fmi2, taylor_fmu(), "u", LogSink::None, false);
        other.restore(&Saved::deserialize(taylor_fmu(), &bytes).unwrap());
        assert_eq!(other.stop_time, Some(2e-6));
        assert!(
            other.do_step("doStep", 1e-6, 1e-6).is_ok(),
            "up to stopTime"
        );
        assert_eq!(
            other.do_step("doStep", 2e-6, 1e-6).unwrap_err(),
            Status::Error
        );
        // A forged experiment is refused; bytes without a stopTime (as
        // before) load without one.
        let before = forge(&bytes, |j| j["stop_time"] = serde_json::json!(-1e-6));
        let e = Saved::deserialize(taylor_fmu(), &before).unwrap_err();
        assert!(
            e.contains("stopTime = -0.000001 must be finite and not before"),
            "{e}"
        );
        let old = forge(&bytes, |j| {
            j.as_object_mut().unwrap().remove("stop_time");
        });
        assert_eq!(
            Saved::deserialize(taylor_fmu(), &old).unwrap().stop_time,
            None
        );
    }

    /// The bytes of a coarse FMI 3 state after one step.
    fn stepped_bytes() -> Vec<u8> {
        let mut inst = coarse(Standard::Fmi3);
        inst.enter_initialization_mode();
        inst.exit_initialization_mode();
        inst.do_step("doStep", 0.0, 1e-6).unwrap();
        inst.save().serialize(taylor_fmu())
    }

    #[test]
    fn cut_lengthened_foreign_and_old_states_are_refused() {
        let fmu = taylor_fmu();
        let bytes = stepped_bytes();
        let header = state_header(fmu).len();
        assert!(bytes.starts_with(b"TaylorImpact FMU state v2 postcard\n{"));
        assert_eq!(
            Saved::serialize(&Saved::deserialize(fmu, &bytes).unwrap(), fmu),
            bytes
        );
        let cuts = (0..bytes.len())
            .step_by(37)
            .chain(bytes.len() - 40..bytes.len());
        for len in cuts {
            let e = Saved::deserialize(fmu, &bytes[..len]).unwrap_err();
            let named = if len < header {
                e == "the bytes are not a serialized TaylorImpact FMU state"
                    || e == "the serialized state comes from a different version of the FMU"
            } else {
                e.starts_with("invalid serialized state: ")
            };
            assert!(named, "cut to {len}: {e}");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        let e = Saved::deserialize(fmu, &longer).unwrap_err();
        assert!(e.contains("1 bytes follow its end"), "{e}");
        // A state of another FMU, of another build, of the JSON encoding.
        let foreign = [b"NohImpact".as_slice(), &bytes[12..]].concat();
        let e = Saved::deserialize(fmu, &foreign).unwrap_err();
        assert_eq!(e, "the bytes are not a serialized TaylorImpact FMU state");
        let mut other = bytes.clone();
        other[header - 3] ^= 1;
        let e = Saved::deserialize(fmu, &other).unwrap_err();
        assert!(e.contains("different version"), "{e}");
        let json = fmu.state_to_json(&bytes).unwrap();
        let v1 = format!("TaylorImpact FMU state v1\n{}\n{json}", fmu.token());
        let e = Saved::deserialize(fmu, v1.as_bytes()).unwrap_err();
        assert!(e.contains("version 1 (JSON)"), "{e}");
    }

    /// The forgeries the fmpy tests made when the state was JSON, now made
    /// on the typed state: each refused, naming what is wrong.
    #[test]
    fn forged_parameters_masses_particles_and_records_are_refused() {
        let bytes = stepped_bytes();
        type Edit = fn(&mut serde_json::Value);
        let edits: [(Edit, &str); 4] = [
            (
                |j| j["scene"]["params"]["Taylor"]["density"] = serde_json::json!(-5.0),
                "density",
            ),
            (
                |j| j["sim"]["solver"]["Taylor"]["mass"] = serde_json::json!([1.0]),
                "masses",
            ),
            (
                |j| {
                    j["sim"]["solver"]["Taylor"]["vel"]
                        .as_array_mut()
                        .unwrap()
                        .pop();
                },
                "velocities",
            ),
            (
                |j| j["sim"]["record_interval"] = serde_json::json!(0.0),
                "record",
            ),
        ];
        // Each refused when it is encoded (a part the state does not hold)
        // or read back.
        for (edit, why) in edits {
            let mut json = taylor_fmu().state_to_json(&bytes).unwrap();
            edit(&mut json);
            match taylor_fmu()
                .state_from_json(json)
                .and_then(|b| Saved::deserialize(taylor_fmu(), &b))
            {
                Ok(_) => panic!("{why}: the forged state was accepted"),
                Err(e) => assert!(e.contains(why), "{e} should name {why}"),
            }
        }
        assert!(Saved::deserialize(taylor_fmu(), &forge(&bytes, |_| {})).is_ok());
    }

    /// Doubles can be NaN or infinite in postcard (not in JSON): each of a
    /// state's doubles, replaced by one of them wherever its bits stand,
    /// makes a state that is refused.
    #[test]
    fn non_finite_numbers_anywhere_in_a_state_are_refused() {
        let fmu = taylor_fmu();
        let bytes = stepped_bytes();
        let header = state_header(fmu).len();
        fn floats(v: &serde_json::Value, out: &mut Vec<f64>) {
            match v {
                serde_json::Value::Number(n) if n.is_f64() => out.push(n.as_f64().unwrap()),
                serde_json::Value::Array(a) => a.iter().for_each(|x| floats(x, out)),
                serde_json::Value::Object(o) => o.values().for_each(|x| floats(x, out)),
                _ => {}
            }
        }
        let mut values = Vec::new();
        floats(&fmu.state_to_json(&bytes).unwrap(), &mut values);
        // Whole numbers (0, 1, ...) also stand in the bytes of larger ones.
        values.retain(|x| x.fract() != 0.0);
        values.sort_by(f64::total_cmp);
        values.dedup();
        assert!(values.len() > 500, "{}", values.len());
        let mut forged = 0;
        for (k, v) in values.iter().enumerate() {
            let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][k % 3];
            let pattern = v.to_le_bytes();
            let mut data = bytes.clone();
            let mut at = header;
            let mut found = false;
            while at + 8 <= data.len() {
                if data[at..at + 8] == pattern {
                    data[at..at + 8].copy_from_slice(&bad.to_le_bytes());
                    found = true;
                    at += 8;
                } else {
                    at += 1;
                }
            }
            assert!(found, "{v} is in the bytes");
            forged += 1;
            match Saved::deserialize(fmu, &data) {
                Ok(_) => panic!("{v} -> {bad}: the state was accepted"),
                Err(e) => assert!(
                    e.starts_with("invalid serialized state: "),
                    "{v} -> {bad}: {e}"
                ),
            }
        }
        assert_eq!(forged, values.len());
    }

    /// An initialized FMI 3 instance of the 3-D FMU at 3 nodes across the
    /// radius.
    fn taylor3d_instance() -> Instance {
        let fmu = Fmu::named("Taylor3dImpact").expect("the registry declares the 3-D FMU");
        let mut inst = Instance::new(Standard::Fmi3, fmu, "t3d", LogSink::None, false);
        let pr = vr_in(fmu, "particles_radial");
        assert_eq!(inst.set("set", &[pr], &[3.0], VarType::Int32), Status::Ok);
        assert_eq!(inst.enter_initialization_mode(), Status::Ok);
        assert_eq!(inst.exit_initialization_mode(), Status::Ok);
        inst
    }

    /// Steps `inst` from `t` by 1 us until the run ends; the bits of its
    /// outputs, its clock and every particle field then.
    fn bits_at_the_end(inst: &mut Instance, mut t: f64) -> Vec<u64> {
        while !inst.at_end {
            inst.do_step("doStep", t, 1e-6).unwrap();
            t += 1e-6;
        }
        run_bits(inst.sim.as_ref().unwrap())
    }

    /// The bits of a run's clock, outputs and particle fields.
    fn run_bits(sim: &Simulation) -> Vec<u64> {
        let mut v = vec![sim.time(), sim.steps() as f64];
        v.extend(sim.observables());
        for f in sim.field_specs() {
            v.extend(sim.field(f.name).unwrap());
        }
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The 3-D FMU's state: a run saved mid-way (its postcard bytes),
    /// restored into another instance and stepped to the end, gives the
    /// bits of the run that was not interrupted, and of `Simulation` on
    /// the same scene; forged states are refused with what is wrong.
    #[test]
    fn taylor3d_fmu_state_resumes_to_the_bits_of_the_whole_run() {
        let mut whole = taylor3d_instance();
        let fmu = whole.fmu;
        let whole_bits = bits_at_the_end(&mut whole, 0.0);
        let mut scene = Scene::builtin("taylor3d").unwrap();
        scene.set("particles_radial", 3.0).unwrap();
        let mut sim = Simulation::new(scene).unwrap();
        sim.run().unwrap();
        assert_eq!(sim.observable("at_rest"), Some(1.0));
        assert_eq!(whole_bits, run_bits(&sim), "the FMU runs the scene's run");
        let mut inst = taylor3d_instance();
        let mut t = 0.0;
        for _ in 0..10 {
            inst.do_step("doStep", t, 1e-6).unwrap();
            t += 1e-6;
        }
        let bytes = inst.save().serialize(fmu);
        assert!(bytes.starts_with(b"Taylor3dImpact FMU state v2 postcard\n{"));
        let mut other = Instance::new(Standard::Fmi2, fmu, "u", LogSink::None, false);
        other.restore(&Saved::deserialize(fmu, &bytes).unwrap());
        assert_eq!(bits_at_the_end(&mut other, t), whole_bits, "restored");
        assert_eq!(bits_at_the_end(&mut inst, t), whole_bits, "not saved");

        // Forged: each refused, naming what is wrong, when it is encoded
        // (a part the state does not hold) or read back; a Taylor state too.
        let forge = |edit: fn(&mut serde_json::Value)| {
            let mut json = fmu.state_to_json(&bytes).unwrap();
            edit(&mut json);
            fmu.state_from_json(json)
        };
        type Edit = fn(&mut serde_json::Value);
        let edits: [(Edit, &str); 4] = [
            (
                |j| j["sim"]["solver"]["Taylor3d"]["mass"] = serde_json::json!([1.0]),
                "masses",
            ),
            (
                |j| {
                    j["sim"]["solver"]["Taylor3d"]["pos"]
                        .as_array_mut()
                        .unwrap()
                        .pop();
                },
                "positions",
            ),
            (
                |j| j["sim"]["solver"]["Taylor3d"]["temp"][4] = serde_json::json!(-1.0),
                "temperatures",
            ),
            (
                |j| j["scene"]["params"]["Taylor3d"]["damping"] = serde_json::json!(0.9),
                "damping",
            ),
        ];
        for (edit, why) in edits {
            match forge(edit).and_then(|b| Saved::deserialize(fmu, &b)) {
                Ok(_) => panic!("{why}: the forged state was accepted"),
                Err(e) => assert!(e.contains(why), "{e} should name {why}"),
            }
        }
        assert!(Saved::deserialize(fmu, &forge(|_| {}).unwrap()).is_ok());
        let e = Saved::deserialize(fmu, &stepped_bytes()).unwrap_err();
        assert_eq!(e, "the bytes are not a serialized Taylor3dImpact FMU state");
        let e = Saved::deserialize(taylor_fmu(), &bytes).unwrap_err();
        assert_eq!(e, "the bytes are not a serialized TaylorImpact FMU state");
        // A NaN or an infinity in place of the internal energy (postcard
        // holds them; JSON cannot).
        let energy =
            fmu.state_to_json(&bytes).unwrap()["sim"]["solver"]["Taylor3d"]["energy"]["internal"]
                .as_f64()
                .unwrap();
        assert!(energy > 0.0);
        for bad in [f64::NAN, f64::INFINITY] {
            let mut data = bytes.clone();
            let at = data
                .windows(8)
                .position(|w| w == energy.to_le_bytes())
                .expect("the energy is in the bytes");
            data[at..at + 8].copy_from_slice(&bad.to_le_bytes());
            let e = Saved::deserialize(fmu, &data).unwrap_err();
            assert!(e.contains("clock and energies"), "{bad}: {e}");
        }
    }

    #[test]
    fn state_round_trips_through_bytes() {
        let mut inst = coarse(Standard::Fmi3);
        inst.enter_initialization_mode();
        inst.exit_initialization_mode();
        inst.do_step("doStep", 0.0, 1e-6).unwrap();
        let bytes = inst.save().serialize(taylor_fmu());
        let saved = Saved::deserialize(taylor_fmu(), &bytes).unwrap();
        let out = inst.do_step("doStep", 1e-6, 1e-6).unwrap();
        let a = inst.sim.as_ref().unwrap().observables();
        inst.restore(&saved);
        let out2 = inst.do_step("doStep", 1e-6, 1e-6).unwrap();
        assert_eq!(out, out2);
        let b = inst.sim.as_ref().unwrap().observables();
        assert_eq!(
            a.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            b.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        assert!(Saved::deserialize(taylor_fmu(), b"nonsense").is_err());
    }
}
