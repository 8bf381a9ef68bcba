//! The closed loop: each physics step, obstacles move, the stack hears odometry and its pose
//! estimate, a revolution is taken and planned from every `1 / scan_hz`, the stack commands, the
//! vehicle moves, the judge judges.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use autonomy::PilotCall;
use nalgebra::Isometry2;

use super::external::{Answer, LatePolicy, StackInput, command_of_twist};
use super::observer::{Observer, RevolutionFrame, SensedFrame, StepFrame};
use super::outcome::{EndReason, Event};
use super::report::Progress;
use super::rig::{Rig, start_state};
use super::schedule::Planned;
use crate::error::{Error, Result};
use crate::world::{Captured, Sensor};

impl Rig<'_> {
    /// The loop: each physics step, as a schedule - obstacles move, the stack hears odometry and
    /// its pose estimate, a revolution is taken and planned from every `1 / scan_hz`, the stack
    /// commands, the vehicle moves, the judge judges.
    pub(super) fn drive<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        stop: Option<&AtomicBool>,
        progress: &mut (dyn FnMut(Progress) + Send),
        observer: &mut (dyn Observer + Send),
    ) -> Result<EndReason> {
        let dt = 1.0 / self.config.physics_hz;
        while !self.judge.done() {
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Ok(EndReason::Interrupted);
            }
            if self.t_s > self.timeout_s {
                return Ok(EndReason::TimedOut);
            }
            // No pilot is called while the tug has the aircraft.
            if self.external.is_none()
                && self.towing.is_none()
                && let Some(end) = self.pilot_called()
            {
                return Ok(end);
            }
            if let Some(at_s) = self.walk_around_at_s
                && self.t_s >= at_s
            {
                self.walk_around_at_s = None;
                self.driver.on_walk_around();
                observer.event(self.t_s, &Event::WalkAround)?;
            }
            if !self.start_unseen_told
                && let Some((cells, cell_m)) = self.driver.start_unseen_cells()
            {
                self.start_unseen_told = true;
                let event = Event::StartUnseen {
                    area_m2: cells.len() as f64 * cell_m * cell_m,
                    cell_m,
                    cells_m: cells.iter().map(|c| [c.x, c.y]).collect(),
                };
                observer.event(self.t_s, &event)?;
            }
            let physics = Instant::now();
            self.move_obstacles();
            self.split.physics += physics.elapsed().as_secs_f64();
            let truth = self.state.world_from_vehicle();
            self.sense_pose(&truth);
            let command = if self.external.is_some() {
                if self.step.is_multiple_of(self.steps_per_scan)
                    && let Some(end) = self.exchange(&truth, observer)?
                {
                    return Ok(end);
                }
                self.external
                    .as_ref()
                    .map(|e| e.command)
                    .unwrap_or_default()
            } else {
                self.own_stack_step(tasks, &truth, observer)?
            };
            let physics = Instant::now();
            // Towed, the stack's command is not the vehicle's.
            let (released, speed_command) = match self.towing.as_mut() {
                Some(tow) => (tow.step(&mut self.state, dt), self.state.speed_m_s),
                None => {
                    self.bicycle.step(&mut self.state, &command, dt);
                    (false, command.speed_m_s)
                }
            };
            self.t_s += dt;
            self.step += 1;
            self.world
                .set_vehicle_pose(&self.state.world_from_vehicle(), self.t_s);
            if let Some(tow) = self.towing.as_mut() {
                tow.note(&self.world);
                if released {
                    self.pushback = Some(tow.report(self.t_s));
                    self.towing = None;
                }
            }
            self.split.physics += physics.elapsed().as_secs_f64();
            let verdict = self
                .judge
                .after_step(self.t_s, &self.state, speed_command, &self.world);
            for (t, event) in self.judge.drain_events() {
                observer.event(t, &event)?;
            }
            if self.external.is_none() {
                self.feel_strikes();
            }
            observer.step(&StepFrame {
                t_s: self.t_s,
                state: &self.state,
                command: &command,
                clearance_m: self.judge.clearance_now_m(),
                real_time_factor: self.t_s / self.wall.elapsed().as_secs_f64().max(1e-9),
                world: &self.world,
            })?;
            if verdict.lap_ended && !self.route.closed() && !self.judge.done() {
                self.restart_open_route()?;
            }
            if self.step.is_multiple_of(100) {
                progress(Progress {
                    sim_time_s: self.t_s,
                    laps_completed: self.judge.laps_completed(),
                    fraction: verdict.fraction,
                });
            }
        }
        Ok(EndReason::Completed)
    }

    /// Whether the shipped stack calls its pilot now, noting what holds the vehicle first: the
    /// run's end, with the call's report kept.
    fn pilot_called(&mut self) -> Option<EndReason> {
        self.holds.note(self.t_s, self.driver.status());
        let call = self.driver.calls_for_pilot(self.t_s)?;
        let unseen = self.driver.start_unseen_cells().map(|(cells, _)| cells);
        let first = self.scenario.objects.len();
        let movers: Vec<usize> = (self.scenario.obstacles.iter().enumerate())
            .filter(|(_, o)| o.motion.is_some())
            .map(|(k, _)| first + k)
            .collect();
        let report = (self.holds).report(self.t_s, call, &self.world, unseen, &movers);
        self.pilot_call = Some(report);
        Some(match call {
            PilotCall::HiddenObstacle => EndReason::WaitingForHiddenObstacle,
            PilotCall::Blocked => EndReason::Blocked,
            PilotCall::WalkAround => EndReason::WaitingForWalkAround,
            PilotCall::Struck => EndReason::Struck,
        })
    }

    /// The strike sensor: a contact begun since the last step with an object the airframe
    /// feels ([`crate::world::ObjectKind::felt_on_contact`]) is told to the shipped stack as a
    /// strike at its time - not where, nor with what.
    fn feel_strikes(&mut self) {
        let contacts = self.world.contacts();
        let felt = contacts[self.contacts_felt..]
            .iter()
            .find(|c| c.kind.felt_on_contact())
            .map(|c| c.time_s);
        self.contacts_felt = contacts.len();
        if let Some(t_s) = felt {
            self.driver.on_strike(t_s);
        }
    }

    /// The shipped stack's part of a step: a revolution when one is due, the late ones
    /// delivered, the watchdog watched; its command.
    fn own_stack_step<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        truth: &Isometry2<f64>,
        observer: &mut (dyn Observer + Send),
    ) -> Result<autonomy::Command> {
        if self.step.is_multiple_of(self.steps_per_scan) {
            self.revolution(tasks, truth, observer)?;
        }
        self.deliver_due(tasks, observer)?;
        let holding = self.driver.watchdog_tripped();
        if holding != self.watchdog_holding {
            self.watchdog_holding = holding;
            self.fault_counts.watchdog_stops += u64::from(holding);
            observer.event(self.t_s, &Event::Watchdog { holding })?;
        }
        Ok(self.driver.command())
    }

    /// The odometry of this step to the stack and the pose source; the pose source's estimate
    /// (through the pose faults) to the stack, its error logged.
    fn sense_pose(&mut self, truth: &Isometry2<f64>) {
        let odometry =
            self.odometry
                .measure(self.t_s, self.state.speed_m_s, self.state.steering_rad);
        self.driver.on_odometry(odometry);
        if let Some(external) = &mut self.external {
            let dt = 1.0 / self.config.physics_hz;
            external.dead_reckon(&odometry, self.bicycle.limits().wheelbase_m, dt);
        }
        let t0 = Instant::now();
        self.pose_source.on_odometry(&odometry);
        let published = self.pose_source.publish(self.t_s, truth);
        self.split.localization += t0.elapsed().as_secs_f64();
        if let Some(mut estimate) = published {
            estimate.world_from_vehicle = self
                .config
                .faults
                .bias_pose(self.t_s, &estimate.world_from_vehicle);
            if let Some(log) = &mut self.localization_errors {
                log.record(self.judge.laps_completed() + 1, truth, &estimate);
            }
            self.driver.on_pose(estimate);
        }
    }

    /// The pose source reads a revolution as the stack receives it.
    pub(super) fn localize(&mut self, captured: &Captured) -> Result<()> {
        let t0 = Instant::now();
        self.pose_source.on_revolution(&captured.revolution)?;
        self.split.localization += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// A revolution: taken, then (at once, or when its latency has passed) mapped and planned
    /// from as the schedule says, shown to the observer.
    fn revolution<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        truth: &Isometry2<f64>,
        observer: &mut (dyn Observer + Send),
    ) -> Result<()> {
        let Some(estimate) = self.driver.estimate().copied() else {
            return Ok(());
        };
        let (index, seed, t_s) = (self.step / self.steps_per_scan, self.seed, self.t_s);
        let faults = &self.config.faults;
        if faults.any() && self.lost.is_lost(faults, seed, index) {
            // It never reaches the stack.
            self.fault_counts.lost_revolutions += 1;
            return Ok(());
        }
        // The fields, not `self.sensor()`: the scheduler and the driver are borrowed mutably below.
        let sensor = Sensor {
            world: &self.world,
            lidar: &self.lidar,
            more: &self.more_lidars,
            faults,
            seed,
            dropped: &self.dropped_returns,
            spurious: &self.spurious_returns,
        };
        let delay_s = faults.delay_s(seed, index);
        if delay_s > 0.0 {
            // Cast now, in the world as it is now; delivered later, in order.
            let captured = sensor.capture(truth, &estimate, index, t_s)?;
            let last = self.in_transit.back().map_or(0.0, |(at, _)| *at);
            self.in_transit
                .push_back(((t_s + delay_s).max(last), captured));
            self.fault_counts.delayed_revolutions += 1;
            return Ok(());
        }
        self.driver.on_revolution(t_s);
        let capture = || sensor.capture(truth, &estimate, index, t_s);
        let (lidar_s, planned) = self.scheduler.revolution(capture, &mut self.driver)?;
        self.planned(tasks, lidar_s, planned, observer)
    }

    /// Delivers the late revolutions whose time has come.
    fn deliver_due<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        observer: &mut (dyn Observer + Send),
    ) -> Result<()> {
        while self
            .in_transit
            .front()
            .is_some_and(|(at, _)| *at <= self.t_s + 1e-9)
        {
            let Some((_, captured)) = self.in_transit.pop_front() else {
                break;
            };
            // The watchdog counts a revolution's age from when it was taken.
            self.driver.on_revolution(captured.revolution.t_s);
            let (lidar_s, planned) = self
                .scheduler
                .revolution(move || Ok(captured), &mut self.driver)?;
            self.planned(tasks, lidar_s, planned, observer)?;
        }
        Ok(())
    }

    /// After a revolution's plan: accounts, shows, and (overlapped) starts mapping the next.
    fn planned<'s>(
        &mut self,
        tasks: &rayon::Scope<'s>,
        lidar_s: f64,
        planned: Option<Planned>,
        observer: &mut (dyn Observer + Send),
    ) -> Result<()> {
        self.split.lidar += lidar_s;
        if let Some(planned) = &planned {
            self.show(planned, observer)?;
        }
        self.scheduler.dispatch(tasks);
        if let Some(planned) = &planned {
            // The localizer reads the revolution once the stack has it (overlapped: the one
            // taken a revolution ago, brought forward to now on odometry), beside the mapping
            // of the next.
            self.localize(&planned.captured)?;
        }
        Ok(())
    }

    /// Accounts for a plan and shows it.
    fn show(&mut self, planned: &Planned, observer: &mut (dyn Observer + Send)) -> Result<()> {
        self.split.mapping += planned.mapping_s;
        self.split.distance_maps += planned.times.distance_maps_s;
        self.split.planning += planned.times.planning_s;
        let Some(plan) = self.driver.last_plan() else {
            // Held before its first plan: no revolution mapped yet (the first, overlapped, is
            // mapped beside this plan), or none at an estimate trusted far enough.
            return Ok(());
        };
        self.judge.on_plan(self.t_s, plan.chosen().offset_m);
        for (t, event) in self.judge.drain_events() {
            observer.event(t, &event)?;
        }
        let map = self
            .scheduler
            .map()
            .ok_or_else(|| Error::Invalid("the online map is not ready".into()))?;
        let v = self.driver.speed_command_m_s();
        let wanted = self.scenario.route.speed_m_s;
        observer.revolution(&RevolutionFrame {
            t_s: self.t_s,
            truth: planned.captured.truth,
            estimate: planned.captured.revolution.world_from_vehicle_estimate,
            revolution: &planned.captured.revolution,
            owners: &planned.captured.owners,
            more_owners: &planned.captured.more_owners,
            map: map.map(),
            plan,
            speed_cmd_m_s: v,
            speed_scale: if wanted > 0.0 { v / wanted } else { 0.0 },
            world: &self.world,
            particles: self.pose_source.particles(),
            pose_estimate: self.driver.estimate().copied(),
            predictions: self.driver.predictions(),
            conflict: self.driver.conflict().copied(),
        })
    }

    /// Run-time obstacles appear, move and go as the scenario says: a mover touching the
    /// vehicle halts for good ([`super::traffic::Traffic::halt`]), the traffic steps to now
    /// around the vehicle's true pose (drivers that yield react to it), then each obstacle's
    /// collider is shown, placed or hidden.
    fn move_obstacles(&mut self) {
        let first = self.scenario.objects.len();
        for k in 0..self.scenario.obstacles.len() {
            if self.world.touches_vehicle(first + k) {
                self.traffic.halt(k);
            }
        }
        self.traffic
            .step(self.t_s, &self.state.world_from_vehicle());
        for (k, o) in self.scenario.obstacles.iter().enumerate() {
            let i = first + k;
            match self.traffic.state(k) {
                Some(m) => {
                    if !self.world.object_active(i) {
                        self.world.set_object_active(i, true);
                    }
                    if o.motion.is_some() {
                        self.world.set_object_pose(i, m.x_m, m.y_m, m.yaw_rad);
                    }
                }
                None if self.world.object_active(i) => self.world.set_object_active(i, false),
                None => {}
            }
        }
    }

    /// An open route starts its next lap from its start pose.
    fn restart_open_route(&mut self) -> Result<()> {
        self.state = start_state(&self.scenario.vehicle.world_from_start);
        self.judge.restart_lap();
        self.driver.restart();
        self.pose_source
            .reset(&self.scenario.vehicle.world_from_start)?;
        // Revolutions of the last lap still in transit would carry its poses into this one.
        self.in_transit.clear();
        self.world
            .set_vehicle_pose(&self.state.world_from_vehicle(), self.t_s);
        Ok(())
    }
}

impl Rig<'_> {
    /// The vehicle's LiDAR in the world, with the run's faults.
    fn sensor(&self) -> Sensor<'_> {
        Sensor {
            world: &self.world,
            lidar: &self.lidar,
            more: &self.more_lidars,
            faults: &self.config.faults,
            seed: self.seed,
            dropped: &self.dropped_returns,
            spurious: &self.spurious_returns,
        }
    }

    /// One control step of an external stack: the revolution taken (unless the faults lose it)
    /// and handed over with the odometry and the pose estimate; its answer checked and held.
    /// The run's end when the stack is late (strict), fails, or asks for the absurd.
    pub(super) fn exchange(
        &mut self,
        truth: &Isometry2<f64>,
        observer: &mut (dyn Observer + Send),
    ) -> Result<Option<EndReason>> {
        // The stamp from the step count, not the summed time: exact, as it goes on the wire.
        let t_s = self.step as f64 / self.config.physics_hz;
        let (index, seed) = (self.step / self.steps_per_scan, self.seed);
        let estimate = self.driver.estimate().copied();
        let faults = &self.config.faults;
        let captured = if faults.any() && self.lost.is_lost(faults, seed, index) {
            self.fault_counts.lost_revolutions += 1;
            None
        } else {
            let sensor = self.sensor();
            let at = estimate.unwrap_or_else(|| autonomy::PoseEstimate::exact(t_s, *truth));
            Some(sensor.capture(truth, &at, index, t_s)?)
        };
        if let Some(c) = &captured {
            self.split.lidar += c.lidar_s;
            self.localize(c)?;
            observer.sensed(&SensedFrame {
                t_s,
                truth: *truth,
                estimate,
                revolution: &c.revolution,
                owners: &c.owners,
                more_owners: &c.more_owners,
                world: &self.world,
            })?;
        }
        let points = captured
            .as_ref()
            .map(|c| super::external::cloud_points(&c.revolution.scan));
        let Some(external) = self.external.as_mut() else {
            return Ok(None);
        };
        let input = StackInput {
            t_s,
            step: index,
            cloud: points.as_deref(),
            odom_from_vehicle: external.odom_from_vehicle,
            odometry: external.odometry,
            estimate,
            truth: *truth,
        };
        external.report.steps += 1;
        let answer = match external.stack.step(&input) {
            Ok(answer) => answer,
            Err(e) => {
                external.report.error = Some(e.to_string());
                return Ok(Some(EndReason::StackFailed));
            }
        };
        match answer {
            Answer::Command(twist) => {
                let held = external.command.steering_rad;
                match command_of_twist(t_s, twist, self.bicycle.limits(), held) {
                    Ok(command) => {
                        external.command = command;
                        external.report.commands += 1;
                    }
                    Err(why) => {
                        external.report.error = Some(why);
                        return Ok(Some(EndReason::StackFailed));
                    }
                }
            }
            Answer::Late { topic } => {
                external.report.late += 1;
                external.report.first_late.get_or_insert((t_s, topic));
                if external.report.policy == LatePolicy::Strict {
                    return Ok(Some(EndReason::StackTimeout));
                }
            }
        }
        Ok(None)
    }
}
