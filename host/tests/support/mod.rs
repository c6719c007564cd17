//! Helpers shared by integration tests and benchmark examples.

pub mod slurm;
