//! The operations on an instance, written once for both standards: reading
//! and writing variables (the host's arrays checked in one place), the
//! getters and setters of types this FMU has none of, and the step.

use super::fmu::{VarKind, VarType, Variable};
use super::instance::{Instance, STEP_MODE, Standard, Status, mask};
use super::log::{CAT_EVENTS, CAT_PROGRESS};
use crate::ffi::{slice, slice_mut};

/// Rounding slack of a time computed from `a` and `b`: 1e-9 of |a| + |b|,
/// finite for any finite `a` and `b` (their sum may overflow: a slack of
/// infinity would accept any time).
fn slack(a: f64, b: f64) -> f64 {
    1e-9 * a.abs() + 1e-9 * b.abs()
}

impl Instance {
    /// A getter or setter of a type this FMU has no variables of (FMI 3
    /// Float32, Int8, ..., String, Binary, Clock; FMI 2 String). In a state
    /// that allows `function` (`mask`, that of the getters or the setters)
    /// an empty list is OK and anything else an Error naming the first value
    /// reference, which is not `what`; in any other state, Error.
    ///
    /// # Safety
    /// `vrs` must be NULL or hold `nvr` value references.
    pub(crate) unsafe fn no_variables(
        &mut self,
        function: &str,
        mask: u32,
        (vrs, nvr): (*const u32, usize),
        what: &str,
    ) -> Status {
        if let Err(s) = self.check_state(function, mask) {
            return s;
        }
        // SAFETY: forwarded contract.
        match unsafe { slice(vrs, nvr) } {
            Some([]) => Status::Ok,
            Some([vr, ..]) => self.fail(&format!("{function}: value reference {vr} is not {what}")),
            None => self.fail(&format!("{function}: the value references are NULL")),
        }
    }

    /// Looks up `vr` and checks its type.
    fn lookup(&mut self, vr: u32, ty: VarType, function: &str) -> Result<Variable, Status> {
        // The table is small (tens of rows): a linear lookup in the
        // instance's copy of [`Fmu::variables`], which allocates nothing.
        // FMI 2 reads and writes an enumeration as an Integer.
        let fmi2 = self.standard == Standard::Fmi2;
        let ty = if fmi2 && ty == VarType::Int32 {
            match self.variables.iter().find(|v| v.vr == vr) {
                Some(v) if v.ty == VarType::Enumeration => VarType::Enumeration,
                _ => ty,
            }
        } else {
            ty
        };
        match self.variables.iter().find(|v| v.vr == vr).copied() {
            Some(v) if v.ty == ty && !(fmi2 && v.kind == VarKind::Time) => Ok(v),
            Some(v) if v.ty != ty => Err(self.fail(&format!(
                "{function}: variable `{}` (value reference {vr}) is of type {:?}, not {:?}",
                v.name, v.ty, ty
            ))),
            _ => Err(self.fail(&format!("{function}: unknown value reference {vr}"))),
        }
    }

    /// Value of a variable as f64 (booleans as 0/1).
    fn value(&mut self, v: &Variable) -> Result<f64, Status> {
        match v.kind {
            VarKind::Time => Ok(self.time),
            VarKind::Parameter(p) => Ok(self
                .scene
                .get(p.name)
                .expect("the table and the scene agree")),
            VarKind::Output(k, _) => {
                self.ensure_sim()?;
                let sim = self.sim.as_ref().expect("built above");
                Ok(sim
                    .observable_at(k)
                    .expect("an output of the scene's table"))
            }
        }
    }

    /// Reads `vrs` of type `ty` as f64.
    pub(crate) fn get(
        &mut self,
        function: &str,
        vrs: &[u32],
        ty: VarType,
    ) -> Result<Vec<f64>, Status> {
        self.check_state(function, mask::GET)?;
        let mut out = Vec::with_capacity(vrs.len());
        for &vr in vrs {
            let v = self.lookup(vr, ty, function)?;
            out.push(self.value(&v)?);
        }
        Ok(out)
    }

    /// Sets `vrs` of type `ty` from f64 values.
    pub(crate) fn set(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &[f64],
        ty: VarType,
    ) -> Status {
        if let Err(s) = self.check_state(function, mask::SET) {
            return s;
        }
        for (&vr, &value) in vrs.iter().zip(values) {
            let v = match self.lookup(vr, ty, function) {
                Ok(v) => v,
                Err(s) => return s,
            };
            match v.kind {
                VarKind::Time => {
                    return self.fail(&format!(
                        "{function}: `time` is the independent variable and cannot be set"
                    ));
                }
                VarKind::Output(..) => {
                    return self.fail(&format!(
                        "{function}: `{}` is an output and cannot be set",
                        v.name
                    ));
                }
                VarKind::Parameter(p) => {
                    if self.state == STEP_MODE {
                        return self.fail(&format!(
                            "{function}: `{}` is a fixed parameter and cannot be changed after initialization",
                            p.name
                        ));
                    }
                    if let Err(e) = self.scene.set(p.name, value) {
                        return self.fail(&e.to_string());
                    }
                    // Rebuilt from the new parameters when next needed.
                    self.sim = None;
                }
            }
        }
        Status::Ok
    }

    /// The checks of a getter's or setter's arrays that every one of them
    /// makes (`fmi3Get*`, `fmi3Set*`, `fmi2Get*`, `fmi2Set*`), in this
    /// order: as many values as value references (FMI 3 passes both
    /// counts, FMI 2 one), then neither array NULL (an empty one may be).
    /// An Error names the argument as the instance's standard does.
    fn host_arrays<'a, V>(
        &mut self,
        function: &str,
        (vrs, nvr): (Option<&'a [u32]>, usize),
        (values, n_values): (Option<V>, usize),
    ) -> Result<(&'a [u32], V), Status> {
        let (vrs_name, values_name) = match self.standard {
            Standard::Fmi3 => ("valueReferences", "values"),
            Standard::Fmi2 => ("vr", "value"),
        };
        if nvr != n_values {
            return Err(self.fail(&format!(
                "{function}: nValues = {n_values} but nValueReferences = {nvr}"
            )));
        }
        let Some(vrs) = vrs else {
            return Err(self.fail(&format!("{function}: {vrs_name} is NULL")));
        };
        let Some(values) = values else {
            return Err(self.fail(&format!("{function}: {values_name} is NULL")));
        };
        Ok((vrs, values))
    }

    /// A getter of either standard: the variables `vrs` of type `ty` into
    /// the host's `values`, each converted by `convert`. FMI 2 passes
    /// `n_values = nvr`.
    ///
    /// # Safety
    /// `vrs` must be NULL or hold `nvr` value references, and `values` NULL
    /// or have room for `n_values` values.
    #[allow(clippy::too_many_arguments)]
    pub(crate) unsafe fn get_values<T>(
        &mut self,
        function: &str,
        ty: VarType,
        vrs: *const u32,
        nvr: usize,
        values: *mut T,
        n_values: usize,
        convert: impl Fn(f64) -> T,
    ) -> Status {
        // SAFETY: forwarded contract.
        let (vrs, out) = unsafe { (slice(vrs, nvr), slice_mut(values, n_values)) };
        let (vrs, out) = match self.host_arrays(function, (vrs, nvr), (out, n_values)) {
            Ok(arrays) => arrays,
            Err(s) => return s,
        };
        match self.get(function, vrs, ty) {
            Ok(v) => {
                for (o, x) in out.iter_mut().zip(v) {
                    *o = convert(x);
                }
                Status::Ok
            }
            Err(s) => s,
        }
    }

    /// A setter of either standard: the variables `vrs` of type `ty` from
    /// the host's `values`, each converted by `convert`. FMI 2 passes
    /// `n_values = nvr`.
    ///
    /// # Safety
    /// `vrs` must be NULL or hold `nvr` value references, and `values` NULL
    /// or hold `n_values` values.
    #[allow(clippy::too_many_arguments)]
    pub(crate) unsafe fn set_values<T: Copy>(
        &mut self,
        function: &str,
        ty: VarType,
        vrs: *const u32,
        nvr: usize,
        values: *const T,
        n_values: usize,
        convert: impl Fn(T) -> f64,
    ) -> Status {
        // SAFETY: forwarded contract.
        let (vrs, vals) = unsafe { (slice(vrs, nvr), slice(values, n_values)) };
        let (vrs, vals) = match self.host_arrays(function, (vrs, nvr), (vals, n_values)) {
            Ok(arrays) => arrays,
            Err(s) => return s,
        };
        let vals: Vec<f64> = vals.iter().map(|&x| convert(x)).collect();
        self.set(function, vrs, &vals, ty)
    }

    /// Advances to `current + h` and returns the FMU's time then: `current +
    /// h`, also when the scene ends in the step or had ended before (the
    /// outputs hold), except for an FMI 3 instance whose host allowed early
    /// return, which returns at the scene's end when that lies inside the
    /// step. Errors have been logged and moved the instance to Terminated.
    pub(crate) fn do_step(&mut self, function: &str, current: f64, h: f64) -> Result<f64, Status> {
        self.check_state(function, mask::DO_STEP)?;
        if h.is_nan() || h <= 0.0 || h.is_infinite() {
            return Err(self.fail(&format!(
                "{function}: communicationStepSize = {h} must be positive and finite"
            )));
        }
        // Hosts add up communication times in floating point: the current
        // time may differ from the FMU's in the last digits of the times
        // added (the start and the steps so far, not this step's size: a
        // huge step must not excuse any current time).
        let tol = slack(self.time, self.start_time);
        if !current.is_finite() || (current - self.time).abs() > tol {
            return Err(self.fail(&format!(
                "{function}: currentCommunicationPoint = {current} s does not match the FMU's time {} s",
                self.time
            )));
        }
        let target = current + h;
        // A step must end at a finite time after the current one: not at
        // infinity (a huge step from a huge time), not lost in rounding (a
        // small step from a huge time).
        if !target.is_finite() || target <= current {
            return Err(self.fail(&format!(
                "{function}: the step would end at t = {target} s (currentCommunicationPoint = {current} s + communicationStepSize = {h} s), not a finite time after the current one"
            )));
        }
        // FMI 2.0 (fmi2SetupExperiment) and FMI 3.0
        // (fmi3EnterInitializationMode): computing past a defined stopTime
        // is an error. Rounding slack: 1e-9 of |stopTime| + step size.
        if let Some(stop) = self.stop_time
            && target > stop + slack(stop, h)
        {
            return Err(self.fail(&format!(
                "{function}: the step would end at t = {target} s (currentCommunicationPoint = {current} s + communicationStepSize = {h} s), past stopTime = {stop} s"
            )));
        }
        if self.at_end {
            // The scene has ended (rod at rest, end_time reached): the step
            // completes and the outputs hold their final values.
            self.time = target;
            self.last_successful_time = target;
            return Ok(target);
        }
        let sim = self.sim.as_mut().expect("built at initialization");
        let result = sim.advance_to(target - self.start_time);
        if let Err(e) = result {
            let msg = format!("{function}: the solver stopped: {e}");
            return Err(self.fail(&msg));
        }
        let sim = self.sim.as_ref().expect("built at initialization");
        let sim_time = self.start_time + sim.time();
        let steps = sim.steps();
        let finished = sim.finished();
        if self.categories[CAT_PROGRESS] {
            // The scene's first observable (for a rod, its length), computed
            // only for a host that listens.
            let first = &sim.observable_specs()[0];
            let value = sim.observable_at(0).expect("every scene has observables");
            self.log(
                Status::Ok,
                CAT_PROGRESS,
                &format!(
                    "t = {sim_time:.6e} s, {steps} steps, {} = {value:.6e} {}",
                    first.name, first.unit
                ),
            );
        }
        // The step completes whether or not the scene ended in it: once
        // it has, the state stays at the scene's end and the outputs hold
        // their final values for the rest of the host's run (docs/guide/fmu.md,
        // "After the scene's end"). An FMI 3 host that allowed early return
        // gets the scene's end as a communication point when it lies before
        // the end of the step (beyond rounding).
        let mut reached = target;
        if finished {
            self.at_end = true;
            let sim = self.sim.as_ref().expect("built at initialization");
            let at_rest = sim.observable("at_rest").unwrap_or(0.0) != 0.0;
            let why = if at_rest {
                "the rod is at rest"
            } else {
                "end_time reached"
            };
            self.log(
                Status::Ok,
                CAT_EVENTS,
                &format!(
                    "{why} at t = {sim_time:.6e} s after {steps} steps; outputs hold their final values"
                ),
            );
            if self.early_return_allowed && sim_time < target - slack(current, h) {
                reached = sim_time;
            }
        }
        self.time = reached;
        self.last_successful_time = reached;
        Ok(reached)
    }
}

/// The exported getters and setters of the types this FMU has variables
/// of, for either standard: each names its value type, the FMI type of its
/// variables and the conversion from (to) f64; [`Instance::get_values`] and
/// [`Instance::set_values`] check the arrays and the variables. The FMI 3
/// functions take the number of values (`[n_values]`), the FMI 2 ones (`[]`)
/// have as many values as value references.
macro_rules! values_of_type {
    ($contract:literal, $n_values:tt;
     $( $(#[$doc:meta])* $fname:ident, $t:ty, $ptr:ident, $ty:ident, $op:ident, $convert:expr; )*) => {$(
        values_of_type!(@one $contract, $n_values, $(#[$doc])* $fname, $t, $ptr, $ty, $op, $convert);
    )*};
    (@one $contract:literal, [$($n_values:ident)?], $(#[$doc:meta])* $fname:ident, $t:ty,
     $ptr:ident, $ty:ident, $op:ident, $convert:expr) => {
        $(#[$doc])*
        ///
        /// # Safety
        #[doc = $contract]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $fname(
            instance: *mut std::ffi::c_void,
            vrs: *const u32,
            nvr: usize,
            values: *$ptr $t,
            $($n_values: usize,)?
        ) -> std::ffi::c_int {
            let n_values = values_of_type!(@count nvr $(, $n_values)?);
            let ty = crate::fmi::fmu::VarType::$ty;
            // SAFETY: forwarded contract.
            (unsafe {
                crate::fmi::instance::with_instance(instance, |inst| {
                    inst.$op(stringify!($fname), ty, vrs, nvr, values, n_values, $convert)
                })
            }) as std::ffi::c_int
        }
    };
    (@count $nvr:ident) => { $nvr };
    (@count $nvr:ident, $n_values:ident) => { $n_values };
}
pub(super) use values_of_type;

#[cfg(test)]
mod tests {
    use super::super::instance::TERMINATED;
    use super::super::log::LogSink;
    use super::super::{coarse, taylor_fmu, vr_of};
    use super::*;

    #[test]
    fn fixed_parameter_refused_after_initialization_and_bad_values_named() {
        let mut inst = Instance::new(Standard::Fmi3, taylor_fmu(), "t", LogSink::None, false);
        let density = vr_of("density");
        assert_eq!(
            inst.set("fmi3SetFloat64", &[density], &[-5.0], VarType::Float64),
            Status::Error
        );
        assert_eq!(inst.state, TERMINATED);
        inst.reset();
        let pr = vr_of("particles_radial");
        assert_eq!(
            inst.set("fmi3SetInt32", &[pr], &[5.0], VarType::Int32),
            Status::Ok
        );
        assert_eq!(inst.enter_initialization_mode(), Status::Ok);
        assert_eq!(inst.exit_initialization_mode(), Status::Ok);
        assert_eq!(
            inst.set("fmi3SetFloat64", &[density], &[7000.0], VarType::Float64),
            Status::Error
        );
        assert_eq!(inst.state, TERMINATED);
    }

    #[test]
    fn step_past_stop_time_is_an_error() {
        let start = |stop: Option<f64>| {
            let mut inst = coarse(Standard::Fmi2);
            inst.stop_time = stop;
            assert_eq!(inst.enter_initialization_mode(), Status::Ok);
            assert_eq!(inst.exit_initialization_mode(), Status::Ok);
            inst
        };
        // Six steps of 0.3 us end one ulp past 1.8 us: rounding, accepted.
        let mut inst = start(Some(1.8e-6));
        let mut t = 0.0;
        for _ in 0..6 {
            inst.do_step("doStep", t, 3e-7).unwrap();
            t += 3e-7;
        }
        assert!(t > 1.8e-6, "the sum overshoots, so the tolerance is used");
        assert_eq!(inst.state, STEP_MODE);
        // One more step goes past stopTime.
        assert_eq!(inst.do_step("doStep", t, 3e-7).unwrap_err(), Status::Error);
        assert_eq!(inst.state, TERMINATED);
        // A single step just past it (1e-6 of stopTime), from the start.
        let mut inst = start(Some(1.8e-6));
        assert_eq!(
            inst.do_step("doStep", 0.0, 1.8e-6 * (1.0 + 1e-6))
                .unwrap_err(),
            Status::Error
        );
        // Without a stop time the same step is fine.
        let mut inst = start(None);
        assert!(inst.do_step("doStep", 0.0, 1.8e-6 * (1.0 + 1e-6)).is_ok());
    }

    /// Issue 65: a step into the scene's end and every step after it
    /// complete (the FMU's time is the end of the step, the instance stays
    /// in step mode), and the outputs hold the bits of the run to rest.
    #[test]
    fn steps_complete_past_the_scenes_end_and_the_outputs_hold() {
        for standard in [Standard::Fmi3, Standard::Fmi2] {
            let mut whole = coarse(standard);
            assert_eq!(whole.enter_initialization_mode(), Status::Ok);
            assert_eq!(whole.exit_initialization_mode(), Status::Ok);
            let mut sim = crate::Simulation::new(whole.scene.clone()).unwrap();
            sim.run().unwrap();
            let bits = |v: Vec<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let final_bits = bits(sim.observables());
            let rest = sim.time();
            let (mut t, h) = (0.0, 1e-6);
            while !whole.at_end {
                assert_eq!(whole.do_step("doStep", t, h).unwrap(), t + h);
                t += h;
                assert_eq!(whole.time, t, "the step completes");
                assert_eq!(whole.last_successful_time, t);
            }
            assert!(t > rest && t - h <= rest, "ended in the step into the rest");
            for _ in 0..5 {
                assert_eq!(whole.do_step("doStep", t, h).unwrap(), t + h);
                t += h;
                assert_eq!(whole.time, t);
                assert_eq!(whole.state, STEP_MODE);
                let s = whole.sim.as_ref().unwrap();
                assert_eq!(bits(s.observables()), final_bits, "{standard:?}");
                assert_eq!(s.time(), rest, "the state stays at the scene's end");
            }
        }
    }

    /// Issue 65: with early return allowed (FMI 3), the step into the
    /// scene's end returns there (OK, the time the rest came), and the
    /// host steps on from it with every step complete.
    #[test]
    fn early_return_at_the_scenes_end_then_steps_on() {
        let mut inst = coarse(Standard::Fmi3);
        inst.early_return_allowed = true;
        assert_eq!(inst.enter_initialization_mode(), Status::Ok);
        assert_eq!(inst.exit_initialization_mode(), Status::Ok);
        let mut sim = crate::Simulation::new(inst.scene.clone()).unwrap();
        sim.run().unwrap();
        let (mut t, h) = (0.0, 1e-6);
        while !inst.at_end {
            t = inst.do_step("doStep", t, h).unwrap();
        }
        assert_eq!(
            t,
            sim.time(),
            "returned at the rest, not at the end of the step"
        );
        assert!(t % h != 0.0);
        for _ in 0..3 {
            assert_eq!(inst.do_step("doStep", t, h).unwrap(), t + h);
            t += h;
            assert_eq!(inst.state, STEP_MODE);
        }
        let bits = |v: Vec<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(inst.sim.as_ref().unwrap().observables()),
            bits(sim.observables())
        );
    }
}
