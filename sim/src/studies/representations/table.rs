//! The comparison as Markdown tables: one per scene, and the headline ratios against the
//! thesis' representation.

use std::fmt::Write as _;

use super::truth::Near;
use super::{Row, SceneResult};

fn mb(bytes: u64) -> String {
    let m = bytes as f64 / 1e6;
    if m >= 100.0 {
        format!("{m:.0}")
    } else if m >= 1.0 {
        format!("{m:.1}")
    } else {
        format!("{m:.2}")
    }
}

/// A ratio: one decimal from 1 up, two significant digits below.
fn ratio(x: f64) -> String {
    if !x.is_finite() {
        "-".into()
    } else if x >= 1.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.2}")
    }
}

fn near_cell(r: &Row, near: Near) -> String {
    r.judged.by_near.get(&near).map_or("-".into(), |e| {
        format!("{} / {} of {}", e.false_alarms, e.misses, e.colliding)
    })
}

/// A count of wrong answers, or "-" where nothing was judged (a real recording).
fn judged(s: &SceneResult, n: usize) -> String {
    if s.poses.0 == 0 {
        "-".into()
    } else {
        n.to_string()
    }
}

/// One scene's table: cost and wrong answers per representation.
pub fn scene_table(s: &SceneResult) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "**{}** ({}; {} revolutions over {:.0} m; {} poses near objects, {} colliding; the route's map: {} blocks)\n",
        s.scenario, s.vehicle, s.revolutions, s.driven_m, s.poses.0, s.poses.1, s.route_blocks
    );
    let nears: Vec<Near> = Near::ALL
        .into_iter()
        .filter(|n| s.rows.iter().any(|r| r.judged.by_near.contains_key(n)))
        .collect();
    let mut head = "| representation | memory, window / route (MB) | insert (ms/rev) | distance update (ms) | pose check (us) | false alarms | misses |".to_string();
    for n in &nears {
        let _ = write!(head, " {}: false alarms / misses of colliding |", n.name());
    }
    let _ = writeln!(t, "{head}");
    let _ = writeln!(t, "|{}", "---|".repeat(7 + nears.len()));
    for r in &s.rows {
        let update = r
            .update_ms
            .map_or_else(|| "-".into(), |u| format!("{u:.2} ({})", r.update_kind));
        let _ = write!(
            t,
            "| {} | {} / {} | {} | {} | {} | {} | {} |",
            r.name,
            mb(r.memory_window_bytes),
            mb(r.memory_route_bytes),
            r.insert_ms
                .map_or_else(|| "-".into(), |ms| format!("{ms:.2}")),
            update,
            if r.judged.pose_check_ns.is_finite() {
                format!("{:.2}", r.judged.pose_check_ns / 1e3)
            } else {
                "-".into()
            },
            judged(s, r.judged.all.false_alarms),
            judged(s, r.judged.all.misses)
        );
        for n in &nears {
            let _ = write!(t, " {} |", near_cell(r, *n));
        }
        let _ = writeln!(t);
    }
    t
}

/// The headline: per scene, how many times less memory and insertion time the thesis'
/// representation takes than each other one, and the wrong answers side by side.
pub fn headline(results: &[SceneResult]) -> String {
    let mut t = String::from(
        "| scene | against | memory: times less | insertion: times less | wrong answers, thesis' vs other (false alarms + misses) |\n|---|---|---|---|---|\n",
    );
    for s in results {
        let Some(thesis) = s.rows.first() else {
            continue;
        };
        for r in s
            .rows
            .iter()
            .skip(1)
            .filter(|r| !r.name.contains("diagnostic"))
        {
            let _ = writeln!(
                t,
                "| {} | {} | {} | {} | {} + {} vs {} + {} |",
                s.scenario,
                r.name,
                ratio(r.memory_window_bytes as f64 / thesis.memory_window_bytes.max(1) as f64),
                ratio(
                    r.insert_ms.unwrap_or(f64::NAN)
                        / thesis.insert_ms.unwrap_or(f64::NAN).max(1e-9)
                ),
                judged(s, thesis.judged.all.false_alarms),
                judged(s, thesis.judged.all.misses),
                judged(s, r.judged.all.false_alarms),
                judged(s, r.judged.all.misses)
            );
        }
    }
    t
}
