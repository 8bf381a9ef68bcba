//! The vocabulary of a run's outcome: what happened ([`Event`]), what the vehicle did at each
//! pass by an obstacle ([`PassOutcome`], [`Pass`], [`ObstacleReport`]), its contacts and who was
//! at fault ([`JudgedContact`]), its stops ([`Stop`]) and why the run ended ([`EndReason`]).
//! The leaf of the engine: the judge, the observer and the
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

    /// Whether this outcome is what `expect` asks for (contact and clearance aside). For
    /// `yield` the outcome is necessary, not sufficient: no outcome says who went first, so the
    /// judge adds its yield rule (the mover crossed the route before the vehicle's front reached
    /// it, with a positive post-encroachment time, and the vehicle drove on).
    pub fn meets(self, expect: Expectation) -> bool {
        match expect {
            Expectation::PassUnder => self == PassOutcome::Passed,
            Expectation::Deviate => self == PassOutcome::Deviated,
            Expectation::Stop => self == PassOutcome::Stopped,
            Expectation::NoContact => true,
            // Stopped, or slowed and passed or deviated: the judge's yield rule decides.
            Expectation::Yield => self != PassOutcome::Collided,
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
    /// Never moved off: part of the ground its first plan sweeps is ground its LiDAR cannot see
    /// from the start, no walk-around confirmed it (`[vehicle] walk_around`), and after
    /// `pilot_call_after_s` the vehicle called for a pilot (the start-up rule).
    WaitingForWalkAround,
    /// Stood for obstacles in its path (in view or hidden) for `blocked_call_after_s` (60 s),
    /// the vehicle called for a pilot: its way is blocked (an aircraft never steers round).
    Blocked,
    /// The airframe felt a strike (a contact with anything but a person, a cone, a marker,
    /// debris or an edge light), the vehicle stood and called for a pilot: it is inspected
    /// before it moves again.
    Struck,
    /// A stack outside the process ([`super::external`]) gave no command for a control step
    /// within its transport's timeout, under the strict policy.
    StackTimeout,
    /// A stack outside the process failed: its transport or process ended, or it asked for
    /// what no vehicle can do (the report's `stack.error` says which).
    StackFailed,
}

impl EndReason {
    /// How a run that did not complete its laps ended, in words for a person (`None` when it
    /// did): the run's table and the replay's end event say it in brackets.
    pub fn note(self) -> Option<&'static str> {
        match self {
            EndReason::Completed => None,
            EndReason::TimedOut => Some("timed out"),
            EndReason::Interrupted => Some("interrupted"),
            EndReason::WaitingForHiddenObstacle => {
                Some("waiting for a hidden obstacle: pilot called")
            }
            EndReason::Blocked => Some("blocked: pilot called"),
            EndReason::WaitingForWalkAround => {
                Some("waiting for a walk-around of ground it cannot see: pilot called")
            }
            EndReason::Struck => Some("struck: pilot called to inspect the airframe"),
            EndReason::StackTimeout => Some("the external stack did not answer in time"),
            EndReason::StackFailed => Some("the external stack failed"),
        }
    }
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
    /// A mover's smallest time to collision over the run, seconds (both extrapolated at
    /// constant velocity, the vehicle along its arc, 10 s ahead; only the vehicle parts whose
    /// heights overlap the mover's count). `None`: never on a collision course, or not a mover.
    pub min_ttc_s: Option<f64>,
    /// A mover's post-encroachment time, seconds: between the first of the two leaving the
    /// area where their swept footprints overlap and the second entering it (0: in it together;
    /// the smallest over the run's encounters). `None`: the swept footprints never overlap, or
    /// not a mover.
    pub pet_s: Option<f64>,
    /// At that encounter, whether the mover went through first (`None`: together, no conflict
    /// or not a mover).
    pub pet_mover_first: Option<bool>,
}

/// A ground-truth contact and who was at fault: the vehicle moving into it when it began (the
/// stack's fault), standing (struck by a mover), or moving while the object came into room the
/// vehicle already held (struck while moving: the object's doing, see [`HELD_ROOM_S`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct JudgedContact {
    /// The contact.
    #[serde(flatten)]
    pub contact: Contact,
    /// The vehicle's true speed at the step the contact began, m/s (signed along its heading).
    pub vehicle_speed_m_s: f64,
    /// True when the vehicle was moving then (|speed| > 0.05 m/s) and the object, where it
    /// touched, did not already touch the vehicle as it stood [`HELD_ROOM_S`] before: the
    /// stack's fault; false: it stood and was struck, or was struck while moving.
    pub at_fault: bool,
    /// True when the vehicle was moving but the object, where it touched, already touched the
    /// vehicle as it stood [`HELD_ROOM_S`] before: it drove into room the vehicle held (a van
    /// into the tail of a jet moving off), not the vehicle into it.
    pub struck_while_moving: bool,
}

/// Above this true speed (m/s) the vehicle was moving when a contact began: the contact was the
/// stack's fault unless the object came into room the vehicle held.
pub const AT_FAULT_SPEED_M_S: f64 = 0.05;

/// How far back the judge looks for the room the vehicle held, seconds: a contact that begins
/// while the vehicle moves is the object's doing when the object, where it touched, would also
/// touch the vehicle placed where it was this long before. At 8 m/s the vehicle was 4 m back:
/// anything it drives into is at fault; at 0.3 m/s, 0.15 m: a mover into its side or tail is not.
pub const HELD_ROOM_S: f64 = 0.5;

impl JudgedContact {
    /// `contact`, which began while the vehicle's true speed was `vehicle_speed_m_s` (at fault
    /// when moving).
    pub fn new(contact: Contact, vehicle_speed_m_s: f64) -> Self {
        Self::judged(contact, vehicle_speed_m_s, false)
    }

    /// `contact`, which began while the vehicle's true speed was `vehicle_speed_m_s`;
    /// `into_held_room`: the object, where it touched, touched the vehicle as it stood
    /// [`HELD_ROOM_S`] before.
    pub fn judged(contact: Contact, vehicle_speed_m_s: f64, into_held_room: bool) -> Self {
        let moving = vehicle_speed_m_s.abs() > AT_FAULT_SPEED_M_S;
        JudgedContact {
            contact,
            vehicle_speed_m_s,
            at_fault: moving && !into_held_room,
            struck_while_moving: moving && into_held_room,
        }
    }
}

/// A stop of the vehicle (after it first moved).
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
    /// A ground-truth contact began (with the vehicle's speed and whether it was at fault).
    Contact(JudgedContact),
    /// A lap ended.
    Lap {
        /// Lap number (1-based).
        lap: u32,
        /// Its time, seconds.
        time_s: f64,
    },
    /// The crew's walk-around confirmed the ground round the vehicle that its LiDAR cannot see
    /// (`[vehicle] walk_around` at a time): the start-up rule lets it move off.
    WalkAround,
    /// The start-up rule's first check: the ground the first plan would sweep that the LiDAR
    /// cannot see from the start (none: `area_m2` 0 and no cells).
    StartUnseen {
        /// Its area, square metres.
        area_m2: f64,
        /// The cells' side, metres.
        cell_m: f64,
        /// The cells' centres in the world, metres.
        cells_m: Vec<[f64; 2]>,
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
    /// A mover's time to collision with the vehicle dropped under 3 s (once per encounter: again
    /// only after it rose above 5 s or the two were no longer on a collision course).
    Conflict {
        /// The mover's id.
        id: String,
        /// The time to collision, seconds.
        ttc_s: f64,
    },
}
