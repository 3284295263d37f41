//! How sure an estimate is: the power-law noise type at each tau (`noise_id`)
//! and the equivalent degrees of freedom that follow from it (`edf`), counted
//! with the phase points a corner apart where phase noise begins late (`corner`).

pub mod corner;
pub mod edf;
pub mod noise_id;
