//! `meshless_impact.calibrate`: the calibration of the core
//! ([`meshless_impact::calibrate`]) from Python, on the same scene, choices
//! and parameters as the command line's `calibrate`, with the same answer
//! bit for bit. It returns `calibration.json`'s text and the material file;
//! the package's `_calibrate.py` makes them a dict with numpy arrays.

use super::{Choices, build_scene, guard, kwargs, raise};
use meshless_impact::calibrate::{Calibration, Free, LeaveOneOutMethod, Options, read_shots};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// See `meshless_impact.calibrate`: returns (the result as JSON text, the
/// material file's text).
#[pyfunction]
#[pyo3(signature = (scene, shots, free, *, preset=None, strength=None, eos=None, scheme=None,
    preset_file=None, max_runs=400, max_wall=3600.0, coarse=None, fd_step=0.01, xtol=1e-3,
    leave_one_out=None, method="broyden".to_string(), params=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn calibrate(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    shots: std::path::PathBuf,
    free: Vec<(String, f64, f64)>,
    preset: Option<String>,
    strength: Option<String>,
    eos: Option<String>,
    scheme: Option<String>,
    preset_file: Option<std::path::PathBuf>,
    max_runs: usize,
    max_wall: f64,
    coarse: Option<(String, f64)>,
    fd_step: f64,
    xtol: f64,
    leave_one_out: Option<String>,
    method: String,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<(String, String)> {
    guard(py, || {
        let choices = Choices {
            preset,
            strength,
            eos,
            scheme,
            preset_file,
        };
        let params = kwargs(params)?;
        let scene = build_scene(scene, &choices, &params)?.map_err(|e| raise(py, &e))?;
        let problem = (|| {
            let shots = read_shots(&shots, &scene)?;
            let free = free
                .iter()
                .map(|(name, lo, hi)| Free::new(name, *lo, *hi, &scene))
                .collect::<Result<Vec<_>, _>>()?;
            let options = Options {
                max_runs,
                max_wall_s: max_wall,
                coarse,
                fd_step,
                xtol,
                broyden: match method.as_str() {
                    "broyden" => true,
                    "plain" => false,
                    other => {
                        return Err(meshless_impact::Error::UnknownModel {
                            key: "method".into(),
                            name: other.into(),
                            allowed: "broyden, plain".into(),
                        });
                    }
                },
                leave_one_out: leave_one_out
                    .as_deref()
                    .map(LeaveOneOutMethod::named)
                    .transpose()?,
            };
            Calibration::new(scene, free, shots, options)
        })()
        .map_err(|e| raise(py, &e))?;
        let result = py
            .detach(|| problem.run(&|_| {}))
            .map_err(|e| raise(py, &e))?;
        Ok((result.to_json().to_string(), result.material_toml))
    })
}
