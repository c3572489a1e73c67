//! Correspondence channels. Each submodule is one matcher of the paper (algorithms.md A-D).

pub mod gabor;
pub mod hopfield;
pub mod mcgm;
pub mod sgm;
