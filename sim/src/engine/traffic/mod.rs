//! Run-time traffic: where each run-time obstacle is, and how fast it goes, at every physics step
//! ([`Traffic`]). Three kinds of mover:
//!
//! - one that does not react (no `yields_to_vehicle_m`), static or moving, with or without a
//!   speed profile: its closed-form [`Obstacle::state_at`] - so every mover written before
//!   drivers reacted moves bit for bit as it did;
//! - a driver that yields (`yields_to_vehicle_m`): stepped each physics step (arc length, speed,
//!   the stop it heads for, the wait left). **The rule** (the ramp rule: give way to a taxiing
//!   aircraft): at each step, its *stretch* is the part of its own path from its front (its arc
//!   length plus half its length) to its front plus its braking distance at its speed
//!   (`v^2 / 2a`) plus its own length (clamped to the path's end). When any part of the vehicle
//!   (the exact ground projection of any of its URDF collision primitives,
//!   [`aircraft::Part::footprint`], the same parts as the world's part colliders, at the
//!   vehicle's true pose) comes within `yields_to_vehicle_m` of that stretch (measured in plan,
//!   heights ignored: a driver keeps clear of the wings too), it brakes at `a` this step
//!   (down to standing, and it waits); otherwise it speeds up at `a` towards `speed_m_s`, as far
//!   as its next stop or the path's end lets it brake in time. `a` is `acceleration_m_s2`, or
//!   [`REACTIVE_ACCELERATION_M_S2`] (2.0 m/s^2). It starts from rest at its appearance, waits
//!   `wait_s` at each stop, and stands at the path's end. **Making room** (`makes_room_m`, the
//!   ramp rule for a vehicle meeting an aircraft head-on): once it has stood
//!   [`MAKE_ROOM_AFTER_S`] for a vehicle coming towards it (headings within 45 degrees of
//!   opposite) with its near side less than `makes_room_m` beyond the vehicle's widest part
//!   (from the vehicle's centre line), it backs along its path at up to
//!   [`MAKE_ROOM_SPEED_M_S`] over three times the shift it needs (8-30 m), pulling aside on a
//!   smooth curve away from that line, its nose along the curve; from there on its path is
//!   shifted by as much, and it yields on it as before (it may come on until the stretch ahead
//!   is near the vehicle again) and drives on once the vehicle has passed. **Clearing the
//!   way** (the same field, the ramp rule for a vehicle caught in an aircraft's way): once it
//!   has stood as long for a vehicle it is not head-on to, with some of its body ahead of the
//!   vehicle's origin and less than `makes_room_m` beyond the vehicle's widest part from its
//!   centre line, it moves along its path at up to [`MAKE_ROOM_SPEED_M_S`] - on, or back if
//!   that is shorter - to the nearest place where all of its body is that far aside, the way
//!   there passing [`CLEAR_WAY_MARGIN_M`] clear of the vehicle's parts as they stood (it does
//!   not look again while it moves), and yields there as before; having backed out, it also
//!   stands while its body is still ahead of the vehicle's origin (the vehicle has not passed),
//!   however far the vehicle is. Stops it moved past are passed. Once per run, either.
//! - a train's car: it keeps its place behind its lead (`TrainLink::behind_m` along the path)
//!   whatever the lead does - profiles, stops, waits for the vehicle.
//!
//! Whatever its kind, a mover that touches the vehicle halts where it is for the rest of the run
//! (until its `disappears_s`, if any: [`Traffic::halt`]; a train with it): a driver who hits an aircraft stops, a person does not
//! walk on through an airframe. Without it a mover would pass through the vehicle's colliders
//! (they are kinematic) and come out under a wing, where the vehicle moving on meets it again.

use aircraft::footprint::{Footprint, segment_distance, segments_distance};
use nalgebra::{Isometry2, Point2, Vector2};

use crate::scenario::{MoverState, Obstacle, ObstacleMotion, REACTIVE_ACCELERATION_M_S2};

/// Arc lengths closer than this are the same place, metres.
const SAME_PLACE_M: f64 = 1e-9;

/// A driver that makes room does so once it has stood this long for the vehicle, seconds.
pub const MAKE_ROOM_AFTER_S: f64 = 3.0;

/// ... backing (or clearing the way along its path) at up to this speed, m/s.
pub const MAKE_ROOM_SPEED_M_S: f64 = 2.0;

/// A driver clearing the way moves only along a stretch of its path this far from every part
/// of the vehicle (beyond half its width), metres.
pub const CLEAR_WAY_MARGIN_M: f64 = 2.0;

/// Making room: where it started moving, how far it backs (or goes on), and the shift it pulls
/// aside by (zero when it clears the way).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Room {
    /// Arc length it started moving from, metres.
    from_arc_m: f64,
    /// How far it backs along its path, metres (negative: it goes on along it, clearing the
    /// way).
    back_m: f64,
    /// Its full sideways shift, metres (world frame).
    shift: Vector2<f64>,
    /// True once it has moved the whole way.
    done: bool,
}

impl Room {
    /// How far aside it is at arc length `arc_m` (0 to 1, smoothstep), and that fraction's
    /// rate per metre of arc (negative for a room made backing: it grows as the arc falls).
    fn blend(&self, arc_m: f64) -> (f64, f64) {
        if self.done {
            return (1.0, 0.0);
        }
        let u = ((self.from_arc_m - arc_m) / self.back_m).clamp(0.0, 1.0);
        (u * u * (3.0 - 2.0 * u), -6.0 * u * (1.0 - u) / self.back_m)
    }
}

/// What a driver that makes room knows of the vehicle: its true pose and half its span.
#[derive(Clone, Copy, Debug)]
struct VehicleView {
    world_from_vehicle: Isometry2<f64>,
    /// The largest |y| of any part's footprint in the vehicle frame, metres.
    half_span_m: f64,
}

/// The state a yielding driver carries from step to step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Reactive {
    /// Arc length of its centre along its path, metres.
    arc_m: f64,
    /// Speed, m/s.
    speed_m_s: f64,
    /// Index of the stop it heads for (== the number of stops: the path's end).
    next_stop: usize,
    /// Time left to wait at the stop it stands at, seconds (0: not waiting there).
    wait_left_s: f64,
    /// True once it has appeared (it starts from rest at its path's start).
    started: bool,
    /// True while it brakes or stands for the vehicle.
    yielding: bool,
    /// How long it has stood yielding, seconds.
    stood_s: f64,
    /// Making room, once it began to.
    room: Option<Room>,
}

impl Reactive {
    /// How far aside it stands now, having made room (zero before), metres.
    fn shift(&self) -> Vector2<f64> {
        self.room
            .map_or_else(Vector2::zeros, |room| room.shift * room.blend(self.arc_m).0)
    }
}

/// How one obstacle is moved.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Drive {
    /// Closed form ([`Obstacle::state_at`]).
    Planned,
    /// A driver that yields, stepped.
    Yielding(Reactive),
    /// A train's car behind obstacle `lead` by `behind_m` along the path.
    Car { lead: usize, behind_m: f64 },
    /// Halted where it touched the vehicle, for good.
    Halted(MoverState),
}

/// The run-time obstacles of a run, moved step by step.
#[derive(Clone, Debug)]
pub struct Traffic {
    obstacles: Vec<Obstacle>,
    drives: Vec<Drive>,
    states: Vec<Option<MoverState>>,
    /// The vehicle's parts' ground footprints in the vehicle frame.
    parts: Vec<Footprint>,
    /// Radius around the vehicle frame's origin holding every footprint, metres.
    reach_m: f64,
    /// The largest |y| of any footprint in the vehicle frame, metres.
    half_span_m: f64,
    /// Time of the last step, seconds.
    t_s: Option<f64>,
}

impl Traffic {
    /// The traffic of `obstacles` (a scenario's, in its order) around `vehicle`.
    pub fn new(obstacles: &[Obstacle], vehicle: &aircraft::Vehicle) -> Self {
        let parts: Vec<Footprint> = vehicle
            .parts
            .iter()
            .map(aircraft::Part::footprint)
            .collect();
        let reach_m = parts
            .iter()
            .map(|f| {
                let (lo, hi) = f.bounds();
                [(lo.x, lo.y), (lo.x, hi.y), (hi.x, lo.y), (hi.x, hi.y)]
                    .iter()
                    .map(|(x, y)| x.hypot(*y))
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        let half_span_m = parts
            .iter()
            .map(|f| {
                let (lo, hi) = f.bounds();
                lo.y.abs().max(hi.y.abs())
            })
            .fold(0.0, f64::max);
        let drives = obstacles
            .iter()
            .map(|o| match &o.motion {
                Some(ObstacleMotion {
                    train: Some(link), ..
                }) => Drive::Car {
                    lead: link.lead,
                    behind_m: link.behind_m,
                },
                Some(m) if m.yields_to_vehicle_m.is_some() => Drive::Yielding(Reactive::default()),
                _ => Drive::Planned,
            })
            .collect();
        Traffic {
            obstacles: obstacles.to_vec(),
            drives,
            states: vec![None; obstacles.len()],
            parts,
            reach_m,
            half_span_m,
            t_s: None,
        }
    }

    /// Moves every obstacle to time `t_s` (the time of the last step plus a physics step; the
    /// first call starts the clock), the vehicle standing at `world_from_vehicle` (its true
    /// pose) meanwhile.
    pub fn step(&mut self, t_s: f64, world_from_vehicle: &Isometry2<f64>) {
        let dt = self.t_s.map_or(0.0, |last| (t_s - last).max(0.0));
        self.t_s = Some(t_s);
        let vehicle_from_world = world_from_vehicle.inverse();
        for k in 0..self.obstacles.len() {
            let o = &self.obstacles[k];
            let state = if !o.present_at(t_s) {
                None
            } else {
                match (&mut self.drives[k], &o.motion) {
                    (Drive::Yielding(r), Some(m)) => {
                        let size_m = [o.solid.shape.length_m(), o.solid.shape.width_m()];
                        let shift = r.shift();
                        let near = |from_m: f64, to_m: f64, within_m: f64| {
                            near_path(
                                &self.parts,
                                self.reach_m,
                                m,
                                (from_m, to_m, &shift),
                                within_m,
                                &vehicle_from_world,
                            )
                        };
                        let vehicle = VehicleView {
                            world_from_vehicle: *world_from_vehicle,
                            half_span_m: self.half_span_m,
                        };
                        Some(advance(r, m, size_m, dt, near, &vehicle))
                    }
                    (Drive::Halted(at), _) => Some(*at),
                    (Drive::Car { lead, behind_m }, Some(m)) => {
                        self.states.get(*lead).copied().flatten().map(|lead| {
                            m.state_at_arc(lead.arc_m.min(m.length_m()) - *behind_m, lead.speed_m_s)
                        })
                    }
                    _ => o.state_at(t_s),
                }
            };
            self.states[k] = state;
        }
    }

    /// Obstacle `k`, touching the vehicle, halts where it stood at the last step, for the rest of
    /// its presence
    /// (standing: speed 0); a train's car halts its lead, so the whole train stands. An absent
    /// or static obstacle is left as it is.
    pub fn halt(&mut self, k: usize) {
        let Some(state) = self.state(k) else {
            return;
        };
        if self.obstacles[k].motion.is_none() {
            return;
        }
        match self.drives[k] {
            Drive::Halted(_) => {}
            Drive::Car { lead, .. } => self.halt(lead),
            Drive::Planned | Drive::Yielding(_) => {
                self.drives[k] = Drive::Halted(MoverState {
                    speed_m_s: 0.0,
                    ..state
                });
            }
        }
    }

    /// Each obstacle's state at the last step, indexed like the scenario's obstacles (`None`:
    /// absent then).
    pub fn states(&self) -> &[Option<MoverState>] {
        &self.states
    }

    /// Obstacle `k`'s state at the last step (`None`: absent then, or no such obstacle).
    pub fn state(&self, k: usize) -> Option<MoverState> {
        self.states.get(k).copied().flatten()
    }

    /// True when obstacle `k` is a driver that yields and it braked or stood for the vehicle,
    /// or moved to make room or clear its way, at the last step (a train's car: when its lead
    /// did).
    pub fn yielding(&self, k: usize) -> bool {
        match self.drives.get(k) {
            Some(Drive::Yielding(r)) => r.yielding,
            Some(Drive::Car { lead, .. }) => self.yielding(*lead),
            _ => false,
        }
    }
}

/// One step of `dt` of a yielding driver of `size_m` (length, width) along `m`;
/// `near(from, to, within)` says whether the vehicle is within `within` of the stretch of the
/// path between those arc lengths (shifted as far aside as it has made room).
fn advance(
    r: &mut Reactive,
    m: &ObstacleMotion,
    size_m: [f64; 2],
    dt: f64,
    near: impl Fn(f64, f64, f64) -> bool,
    vehicle: &VehicleView,
) -> MoverState {
    let a = m.acceleration().unwrap_or(REACTIVE_ACCELERATION_M_S2);
    let path_m = m.length_m();
    let length_m = size_m[0];
    r.yielding = false;
    if !r.started {
        // It appears at rest at the start of its path.
        *r = Reactive {
            started: true,
            ..Reactive::default()
        };
        return m.state_at_arc(0.0, 0.0);
    }
    if let Some(room) = r.room.filter(|room| !room.done) {
        return backing(r, room, m, a, dt);
    }
    if r.wait_left_s > 0.0 {
        r.wait_left_s -= dt;
        if r.wait_left_s <= 0.0 {
            r.wait_left_s = 0.0;
            r.next_stop += 1;
        }
        return placed(r, m, 0.0);
    }
    let rest_m = m.stops.get(r.next_stop).map_or(path_m, |s| s.at_m);
    if rest_m - r.arc_m <= SAME_PLACE_M {
        r.arc_m = rest_m;
        r.speed_m_s = 0.0;
        if let Some(stop) = m.stops.get(r.next_stop) {
            r.wait_left_s = stop.wait_s;
        }
        return placed(r, m, 0.0);
    }
    let front_m = r.arc_m + 0.5 * length_m;
    let reach_m = front_m + r.speed_m_s * r.speed_m_s / (2.0 * a) + length_m;
    let within_m = m.yields_to_vehicle_m.unwrap_or(0.0);
    r.yielding = front_m < path_m
        && (near(front_m, reach_m.min(path_m), within_m)
            || backed_out_ahead(r, m, size_m, vehicle));
    r.stood_s = if r.yielding && r.speed_m_s <= 0.0 {
        r.stood_s + dt
    } else {
        0.0
    };
    if r.room.is_none() && r.stood_s >= MAKE_ROOM_AFTER_S {
        // Once a second after the first try: a way it cannot clear is looked for again.
        let since = |s: f64| ((s - MAKE_ROOM_AFTER_S) / 1.0).floor();
        let search =
            r.stood_s - dt < MAKE_ROOM_AFTER_S || since(r.stood_s) != since(r.stood_s - dt);
        r.room = make_room(r, m, size_m, vehicle, (&near, search));
    }
    r.speed_m_s = if r.yielding {
        (r.speed_m_s - a * dt).max(0.0)
    } else {
        let can_stop = (2.0 * a * (rest_m - r.arc_m)).sqrt();
        (r.speed_m_s + a * dt).min(m.speed_m_s).min(can_stop)
    };
    r.arc_m = (r.arc_m + r.speed_m_s * dt).min(rest_m);
    placed(r, m, r.speed_m_s)
}

/// Its state at its arc length moving at `speed_m_s` along its path, shifted as far aside as
/// it has made room, its nose along the curve it backs on.
fn placed(r: &Reactive, m: &ObstacleMotion, speed_m_s: f64) -> MoverState {
    let mut state = m.state_at_arc(r.arc_m, speed_m_s);
    if let Some(room) = r.room {
        let rate = room.blend(r.arc_m).1;
        let at = Vector2::new(state.x_m, state.y_m) + r.shift();
        let along = Vector2::new(state.heading_rad.cos(), state.heading_rad.sin());
        let tangent = along + room.shift * rate;
        let heading = tangent.y.atan2(tangent.x);
        state.yaw_rad += heading - state.heading_rad;
        (state.x_m, state.y_m, state.heading_rad) = (at.x, at.y, heading);
    }
    state
}

/// The room a driver of `size_m` (length, width) standing for the vehicle makes, if it must:
/// head-on, it backs and pulls aside ([`Room`]'s shift); otherwise it clears the vehicle's way
/// along its path ([`clear_way`]). `None` when it stands `makes_room_m` clear already, or
/// cannot.
/// `near` is the yield test's; `search`: whether to look for a way to clear now (a head-on
/// driver's room is found at every call).
fn make_room(
    r: &Reactive,
    m: &ObstacleMotion,
    size_m: [f64; 2],
    vehicle: &VehicleView,
    (near, search): (&impl Fn(f64, f64, f64) -> bool, bool),
) -> Option<Room> {
    let clear_m = m.makes_room_m?;
    let here = m.state_at_arc(r.arc_m, 0.0);
    let v = &vehicle.world_from_vehicle;
    // Headings within 45 degrees of opposite: the vehicle comes towards it.
    let opposite = -(here.heading_rad - v.rotation.angle()).cos();
    if opposite < std::f64::consts::FRAC_1_SQRT_2 {
        return if search {
            clear_way(r, m, size_m, vehicle, (clear_m, near))
        } else {
            None
        };
    }
    let local = v.inverse() * Point2::new(here.x_m, here.y_m);
    let wanted_m = vehicle.half_span_m + 0.5 * size_m[1] + clear_m;
    let need_m = wanted_m - local.y.abs();
    if need_m <= 0.0 {
        return None;
    }
    // Away from the vehicle's centre line, on the side it stands (on the line: the vehicle's
    // left, the driver's right).
    let side = if local.y < 0.0 { -1.0 } else { 1.0 };
    Some(Room {
        from_arc_m: r.arc_m,
        back_m: (3.0 * need_m).clamp(8.0, 30.0),
        shift: v.rotation * Vector2::new(0.0, side * need_m),
        done: false,
    })
}

/// A driver's body of `size_m` (length, width) at arc length `arc_m` of `m`, seen from the
/// vehicle: its centre in the vehicle frame, and its half extents along and across that frame.
fn body_seen(
    m: &ObstacleMotion,
    arc_m: f64,
    size_m: [f64; 2],
    vehicle: &VehicleView,
) -> (Point2<f64>, f64, f64) {
    let v = &vehicle.world_from_vehicle;
    let s = m.state_at_arc(arc_m, 0.0);
    let c = v.inverse() * Point2::new(s.x_m, s.y_m);
    let (sin, cos) = (s.yaw_rad - v.rotation.angle()).sin_cos();
    let along = 0.5 * (size_m[0] * cos.abs() + size_m[1] * sin.abs());
    let across = 0.5 * (size_m[0] * sin.abs() + size_m[1] * cos.abs());
    (c, along, across)
}

/// True when `r` backed out of the vehicle's way (a room with no shift, made backing) and some
/// of its body is still ahead of the vehicle's origin: the vehicle has not passed it yet.
fn backed_out_ahead(
    r: &Reactive,
    m: &ObstacleMotion,
    size_m: [f64; 2],
    vehicle: &VehicleView,
) -> bool {
    r.room
        .is_some_and(|room| room.done && room.shift == Vector2::zeros() && room.back_m > 0.0)
        && {
            let (c, along, _) = body_seen(m, r.arc_m, size_m, vehicle);
            c.x + along > 0.0
        }
}

/// Where a driver of `size_m` (length, width) at arc length `r.arc_m` clears the vehicle's
/// way, as a [`Room`] with no shift (`back_m` negative: on along its path): `None` when none of
/// its body is ahead of the vehicle's origin, it is `clear_m` beyond the vehicle's widest part
/// from its centre line already, or no place on its path is that it reaches along a stretch
/// `near` (the yield test's) finds [`CLEAR_WAY_MARGIN_M`] clear of the vehicle.
fn clear_way(
    r: &Reactive,
    m: &ObstacleMotion,
    size_m: [f64; 2],
    vehicle: &VehicleView,
    (clear_m, near): (f64, &impl Fn(f64, f64, f64) -> bool),
) -> Option<Room> {
    let clear = |arc_m: f64| {
        let (c, _, across) = body_seen(m, arc_m, size_m, vehicle);
        c.y.abs() - across >= vehicle.half_span_m + clear_m
    };
    let (c, along, _) = body_seen(m, r.arc_m, size_m, vehicle);
    if c.x + along <= 0.0 || clear(r.arc_m) {
        return None;
    }
    const STEP_M: f64 = 0.25;
    let path_m = m.length_m();
    let steps = (path_m / STEP_M).ceil() as usize;
    // The stretch its body sweeps on the way to `to_m` passes clear of the vehicle.
    let free = |to_m: f64| {
        let half = 0.5 * size_m[0];
        let (lo, hi) = (r.arc_m.min(to_m) - half, r.arc_m.max(to_m) + half);
        !near(
            lo.max(0.0),
            hi.min(path_m),
            CLEAR_WAY_MARGIN_M + 0.5 * size_m[1],
        )
    };
    let on = (1..=steps)
        .map(|k| (r.arc_m + k as f64 * STEP_M).min(path_m))
        .find(|&a| clear(a))
        .filter(|&a| free(a));
    let back = (1..=steps)
        .map(|k| (r.arc_m - k as f64 * STEP_M).max(0.0))
        .find(|&a| clear(a))
        .filter(|&a| free(a));
    let to_m = match (on, back) {
        (Some(on), Some(back)) if r.arc_m - back < on - r.arc_m => back,
        (Some(on), _) => on,
        (None, back) => back?,
    };
    Some(Room {
        from_arc_m: r.arc_m,
        back_m: r.arc_m - to_m,
        shift: Vector2::zeros(),
        done: false,
    })
}

/// One step of `dt` making `room`: along its path (back, or on when clearing the way forward)
/// at up to [`MAKE_ROOM_SPEED_M_S`], braking to stand at the curve's end, where the room is
/// made.
fn backing(r: &mut Reactive, room: Room, m: &ObstacleMotion, a: f64, dt: f64) -> MoverState {
    let to_m = room.from_arc_m - room.back_m;
    let left_m = (r.arc_m - to_m).abs();
    let sign = if to_m < r.arc_m { -1.0 } else { 1.0 };
    let speed = (r.speed_m_s.abs() + a * dt)
        .min(MAKE_ROOM_SPEED_M_S)
        .min((2.0 * a * left_m).sqrt());
    r.yielding = true;
    if left_m - speed * dt <= SAME_PLACE_M {
        r.arc_m = to_m;
        r.speed_m_s = 0.0;
        r.room = Some(Room { done: true, ..room });
        // Stops it went on past are passed.
        while m
            .stops
            .get(r.next_stop)
            .is_some_and(|s| s.at_m < r.arc_m - SAME_PLACE_M)
        {
            r.next_stop += 1;
        }
        return placed(r, m, 0.0);
    }
    r.arc_m += sign * speed * dt;
    r.speed_m_s = sign * speed;
    placed(r, m, r.speed_m_s)
}

/// True when any of the vehicle's `parts` (footprints in its frame, all within `reach_m` of its
/// origin) lies within `within_m` of the stretch of `m`'s path between arc lengths `from_m` and
/// `to_m`, moved by `shift`, in plan; `vehicle_from_world` places the path in the vehicle's
/// frame.
fn near_path(
    parts: &[Footprint],
    reach_m: f64,
    m: &ObstacleMotion,
    (from_m, to_m, shift): (f64, f64, &Vector2<f64>),
    within_m: f64,
    vehicle_from_world: &Isometry2<f64>,
) -> bool {
    let stretch = stretch(m, from_m, to_m);
    let local: Vec<Point2<f64>> = stretch
        .iter()
        .map(|p| vehicle_from_world * (p + shift))
        .collect();
    let origin = Point2::origin();
    local.windows(2).any(|w| {
        segment_distance(&origin, &w[0], &w[1]) <= reach_m + within_m
            && parts
                .iter()
                .any(|f| footprint_segment_distance(f, &w[0], &w[1]) < within_m)
    }) || (local.len() == 1 && parts.iter().any(|f| f.distance(&local[0]) < within_m))
}

/// The points of `m`'s path between arc lengths `from_m` and `to_m` (>= `from_m`): both ends
/// and the vertices between.
fn stretch(m: &ObstacleMotion, from_m: f64, to_m: f64) -> Vec<Point2<f64>> {
    let at = |s: f64| {
        let p = m.state_at_arc(s, 0.0);
        Point2::new(p.x_m, p.y_m)
    };
    let mut points = vec![at(from_m)];
    let mut arc_m = 0.0;
    for w in m.path_m.windows(2) {
        arc_m += (w[1] - w[0]).norm();
        if arc_m > from_m && arc_m < to_m {
            points.push(w[1]);
        }
    }
    if to_m > from_m {
        points.push(at(to_m));
    }
    points
}

/// Distance between a footprint and the segment `a`-`b` (0 when they meet).
fn footprint_segment_distance(f: &Footprint, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
    match f {
        Footprint::Disc(disc) => (segment_distance(&disc.center, a, b) - disc.radius_m).max(0.0),
        Footprint::Polygon(poly) => {
            if poly.contains(a) || poly.contains(b) {
                return 0.0;
            }
            let v = poly.vertices();
            (0..v.len())
                .map(|i| segments_distance(a, b, &v[i], &v[(i + 1) % v.len()]))
                .fold(f64::INFINITY, f64::min)
        }
    }
}

#[cfg(test)]
mod tests;
