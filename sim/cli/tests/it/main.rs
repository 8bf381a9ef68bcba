//! The `taxi-sim` binary end to end, one test binary (`cargo test -p taxi-sim --test it`): exit
//! codes, messages on bad input, files written; the campaigns, hostile inputs, replay options,
//! tuning sweeps and `bench figures`' refusals that go through the binary. Paths are from this
//! package (`sim/cli`): the shipped scenarios are `../../scenarios`, the fixtures of `sim/tests`
//! are `../tests`.

/// Runs the binary with `args` in `dir`: its exit code (-1 when a signal ended it), stdout and
/// stderr.
fn taxi_sim_in(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

mod airport;
mod campaign;
mod cli;
mod figures;
mod hostile;
mod pcap;
mod regress;
mod replay;
#[path = "../../../tests/it/smoke_campaign.rs"]
mod smoke_campaign;
mod stack;
mod tune;
