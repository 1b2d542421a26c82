//! System tests: the `testbed` binary as a user runs it.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

mod bad_input;
mod compare;
mod light_arms;
mod live;
mod liveness;
mod log_integrity;
mod log_replay;
mod many_joints;
mod mjcf_arms;
mod outputs;
mod policy_onnx;
mod process_tree;
mod python;
mod python_in_process;
mod realtime_integrity;
mod replace_nodes;
mod robots;
mod run_cli;
mod scenarios;
mod sim_cli;
mod slurm;
mod sweep;
mod trajectories;
mod util;
mod verdicts;
mod workflow;
