//! The lines of the `events` text log: the run's events and its end, each with its level.

use rerun::components::TextLogLevel;

use crate::engine::{Event, RunReport};

/// An event's line and level (a `TextLogLevel` name).
pub(super) fn event_line(event: &Event) -> (String, &'static str) {
    match event {
        Event::Stop { route_s_m } => (
            format!("stop at {route_s_m:.1} m along the route"),
            TextLogLevel::WARN,
        ),
        Event::Resume { stopped_s } => {
            (format!("resume after {stopped_s:.1} s"), TextLogLevel::INFO)
        }
        Event::Deviate { offset_m } => (
            format!("deviate: offset {offset_m:+.2} m"),
            TextLogLevel::INFO,
        ),
        Event::BackOnRoute => ("back on the route".to_string(), TextLogLevel::INFO),
        Event::WalkAround => (
            "walk-around: the crew confirms the ground the LiDAR cannot see".to_string(),
            TextLogLevel::INFO,
        ),
        Event::StartUnseen { area_m2, .. } if *area_m2 > 0.0 => (
            format!(
                "start-up rule: {area_m2:.1} m2 of the ground the first plan sweeps is out of the LiDAR's sight (world/start/unseen): waiting for the walk-around"
            ),
            TextLogLevel::WARN,
        ),
        Event::StartUnseen { .. } => (
            "start-up rule: the ground the first plan sweeps is all in the LiDAR's sight"
                .to_string(),
            TextLogLevel::INFO,
        ),
        Event::Watchdog { holding: true } => (
            "watchdog: no fresh LiDAR revolution, stopping".to_string(),
            TextLogLevel::WARN,
        ),
        Event::Watchdog { holding: false } => (
            "watchdog: revolutions are back".to_string(),
            TextLogLevel::INFO,
        ),
        Event::Contact(j) => {
            let c = &j.contact;
            let fault = if j.at_fault {
                format!("at fault, moving at {:.2} m/s", j.vehicle_speed_m_s)
            } else if j.struck_while_moving {
                format!("struck while moving at {:.2} m/s", j.vehicle_speed_m_s)
            } else {
                "struck while standing".to_string()
            };
            (
                format!(
                    "contact: {} ({:?}) touched by {} ({fault})",
                    c.object, c.kind, c.part
                ),
                TextLogLevel::ERROR,
            )
        }
        Event::Conflict { id, ttc_s } => (
            format!("conflict: {id}, time to collision {ttc_s:.1} s"),
            TextLogLevel::WARN,
        ),
        Event::Lap { lap, time_s } => (format!("lap {lap} in {time_s:.1} s"), TextLogLevel::INFO),
        Event::Pass { id, outcome, met } => (
            format!(
                "pass {id}: {outcome}{}",
                if *met { "" } else { " (not as expected)" }
            ),
            if *met {
                TextLogLevel::INFO
            } else {
                TextLogLevel::WARN
            },
        ),
    }
}

/// The run's last line: laps, contacts and whether every expectation held; and its level.
pub(super) fn end_line(report: &RunReport) -> (String, &'static str) {
    let text = format!(
        "end: {}/{} laps, {} contacts ({} at fault, {} struck), {}{}",
        report.laps_completed,
        report.laps,
        report.contacts.len(),
        report.contacts_at_fault,
        report.contacts_struck,
        if report.expectations_met {
            "every expectation held"
        } else {
            "expectations not met"
        },
        report
            .end
            .note()
            .map(|n| format!(" ({n})"))
            .unwrap_or_default()
    );
    let level = if report.expectations_met {
        TextLogLevel::INFO
    } else {
        TextLogLevel::WARN
    };
    (text, level)
}
