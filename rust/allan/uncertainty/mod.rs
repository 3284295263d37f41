//! How sure an estimate is: the power-law noise type at each tau (`noise_id`)
//! and the equivalent degrees of freedom that follow from it (`edf`).

pub mod edf;
pub mod noise_id;
