//! Material models, one per file: equations of state and strength models are
//! separate and composed per scene.

pub mod eos;
pub mod ideal_gas;
pub mod johnson_cook;
