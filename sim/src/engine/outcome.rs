//! The vocabulary of a run's outcome: what happened ([`Event`]), what the vehicle did at each
//! pass by an obstacle ([`PassOutcome`], [`Pass`], [`ObstacleReport`]), its stops ([`Stop`]) and
//! why the run ended ([`EndReason`]). The leaf of the engine: the judge, the observer and the
//! report all point down at it.

use serde::Serialize;

use crate::scenario::Expectation;
use crate::world::Contact;

/// What the vehicle did at one pass by an obstacle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PassOutcome {
    /// Neither deviated nor stopped.
    Passed,
    /// Left the route by more than 0.5 m near it.
    Deviated,
    /// Stopped before it.
    Stopped,
    /// Touched it.
    Collided,
}

impl PassOutcome {
    /// The name used in reports.
    pub fn as_str(self) -> &'static str {
        match self {
            PassOutcome::Passed => "passed",
            PassOutcome::Deviated => "deviated",
            PassOutcome::Stopped => "stopped",
            PassOutcome::Collided => "collided",
        }
    }

    /// Whether this outcome is what `expect` asks for (contact and clearance aside).
    pub fn meets(self, expect: Expectation) -> bool {
        match expect {
            Expectation::PassUnder => self == PassOutcome::Passed,
            Expectation::Deviate => self == PassOutcome::Deviated,
            Expectation::Stop => self == PassOutcome::Stopped,
            Expectation::NoContact => true,
        }
    }
}

impl std::fmt::Display for PassOutcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EndReason {
    /// Every lap asked for was driven.
    Completed,
    /// The time limit (60 s plus four times the laps' length at the route's speed) was reached.
    TimedOut,
    /// Stopped from outside (Ctrl-C).
    Interrupted,
    /// Stopped for an obstacle the sensor could no longer see, the vehicle waited
    /// `pilot_call_after_s` and called for a pilot (the thesis' pilot intervention).
    WaitingForHiddenObstacle,
}

/// One pass of the vehicle by an obstacle.
#[derive(Clone, Debug, Serialize)]
pub struct Pass {
    /// Lap (1-based).
    pub lap: u32,
    /// What the vehicle did.
    pub outcome: PassOutcome,
    /// Smallest ground-truth distance from the obstacle to the vehicle's parts of each level, metres.
    pub min_clearance_m: Vec<f64>,
    /// Largest lateral offset from the route near the obstacle, metres.
    pub max_offset_m: f64,
    /// Whether this pass met the obstacle's expectation: the outcome it expects, no contact, and
    /// no clearance under the scenario's danger distance (when it states one).
    pub met: bool,
}

/// An obstacle and what happened at each pass.
#[derive(Clone, Debug, Serialize)]
pub struct ObstacleReport {
    /// Its id.
    pub id: String,
    /// Its kind.
    pub kind: String,
    /// What the scenario expects.
    pub expected: Expectation,
    /// Every pass.
    pub passes: Vec<Pass>,
}

/// A stop of the vehicle.
#[derive(Clone, Debug, Serialize)]
pub struct Stop {
    /// When it stopped, seconds.
    pub start_s: f64,
    /// When it moved again, seconds (`None`: still stopped at the end).
    pub end_s: Option<f64>,
    /// Where along the route, metres.
    pub route_s_m: f64,
}

/// Something that happened in a run.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    /// The vehicle stopped at this arc length of the route.
    Stop {
        /// Metres along the route.
        route_s_m: f64,
    },
    /// The vehicle moved again after a stop.
    Resume {
        /// How long it stood, seconds.
        stopped_s: f64,
    },
    /// The planner chose a path off the route.
    Deviate {
        /// Target lateral offset, metres (positive: left).
        offset_m: f64,
    },
    /// The planner came back to the route.
    BackOnRoute,
    /// A ground-truth contact began.
    Contact(Contact),
    /// A lap ended.
    Lap {
        /// Lap number (1-based).
        lap: u32,
        /// Its time, seconds.
        time_s: f64,
    },
    /// The stack's watchdog stopped the vehicle (no fresh LiDAR revolution) or let it go again.
    Watchdog {
        /// True when it began holding the vehicle, false when revolutions returned.
        holding: bool,
    },
    /// The vehicle went by a run-time obstacle.
    Pass {
        /// The obstacle's id.
        id: String,
        /// What the vehicle did.
        outcome: PassOutcome,
        /// Whether the scenario's expectation held.
        met: bool,
    },
}
