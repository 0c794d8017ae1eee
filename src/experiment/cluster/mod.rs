//! Tools over a whole results tree: Slurm job arrays ([`slurm`]) and retraining committed runs to
//! check them ([`audit`]).

pub mod audit;
pub mod slurm;
