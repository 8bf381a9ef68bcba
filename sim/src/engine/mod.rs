//! One closed-loop run: the rig that builds its parts and drives the loop ([`run`],
//! [`run_with`]), the schedule that maps and plans each revolution ([`Scheduler`]), the pose
//! sources ([`PoseSource`]: truth, noisy truth, the particle filter), the pose-error log
//! ([`ErrorLog`]), the judge ([`Judge`]: ground truth, passes, stops, laps, contacts and who was at
//! fault, traffic conflicts with movers - `conflict`: time to collision, post-encroachment time -,
//! verdicts), the
//! observer hook ([`Observer`]), the report ([`RunReport`]) and the run-time traffic
//! ([`Traffic`]: each obstacle's pose and speed each step, drivers that yield to the vehicle)
//! and the push-back from a stand (`pushback`: the tug's kinematic tow, [`PushbackReport`]).
//! The vocabulary of a run's outcome ([`Event`], [`PassOutcome`], [`EndReason`], [`Stop`], ...)
//! is the leaf `outcome`, which the judge, the observer and the report all point down at.

mod closed_loop;
mod conflict;
mod external;
mod judge;
mod node;
mod observer;
mod outcome;
mod pilot_call;
mod pose_error;
mod pose_source;
mod pushback;
mod report;
mod rig;
mod schedule;
mod traffic;

pub use external::{
    ABSURD_YAW_RATE_RAD_S, Answer, ExternalStack, LatePolicy, StackInput, StackReport, StackStart,
    Twist, cloud_points, command_of_twist,
};
pub use judge::{DEVIATION_M, Judge, StepVerdict, Verdict};
pub use node::{
    EPOCH_NS, InProcessNode, ShippedNode, WireStep, covariance6, pose_off_wire, pose_on_wire,
    seconds_of_stamp, stamp_ns, wire_step,
};
pub use observer::{
    NoObserver, Observer, Observers, RevolutionFrame, RunStart, SensedFrame, StepFrame,
};
pub use outcome::{
    AT_FAULT_SPEED_M_S, EndReason, Event, JudgedContact, ObstacleReport, Pass, PassOutcome, Stop,
};
pub use pilot_call::{AT_BODY_WITHIN_M, Hold, NEEDLESS_WINDOW_S, PilotCallReport, REAL_WITHIN_M};
pub use pose_error::{
    ErrorLog, ErrorStats, LocalizationErrors, LocalizationReport, localization_misses,
};
pub use pose_source::{LocalizationContext, Localizer, NoisyTruth, PoseSource, Truth, from_config};
pub use pushback::{PushbackReport, TOW_SPEED_M_S};
pub use report::{
    CLOSE_STATIC_M, CLOSEST_STATIC_COUNT, HiddenObstacle, Progress, RunReport, SpeedLowered,
    StaticClearance, TimeSplit,
};
pub use rig::{
    RunHandles, RunSetup, distance_cap_m, distance_map_half_size_m, longest_horizon_m, run,
    run_external, run_with,
};
pub use schedule::{Planned, Scheduler};
pub use traffic::Traffic;
