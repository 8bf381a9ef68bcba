//! The `taxi-sim` binary end to end, one test binary (`cargo test -p taxi-sim --test it`): exit
//! codes, messages on bad input, files written; the campaigns, hostile inputs, replay options
//! and tuning sweeps that go through the binary. Paths are from this package (`sim/cli`): the
//! shipped scenarios are `../../scenarios`, the fixtures of `sim/tests` are `../tests`.

mod campaign;
mod cli;
mod hostile;
mod replay;
mod tune;
