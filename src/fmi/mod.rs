//! FMI 3.0 and FMI 2.0 Co-Simulation glue over the same core (model
//! identifier `TaylorImpact`).
