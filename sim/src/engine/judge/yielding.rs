//! The `yield` rule: what a `yield` pass is judged on, and when it is met.

use crate::engine::conflict::Encroachment;

/// What a `yield` pass is judged on.
#[derive(Clone, Copy, Debug)]
pub(super) struct YieldFacts {
    /// Anything touched the mover during the pass.
    pub(super) contact: bool,
    /// The post-encroachment time since the last pass by it (`None`: no conflict area).
    pub(super) encroachment: Option<Encroachment>,
    /// When the mover was nearest the route's point (`None`: it never came by).
    pub(super) mover_crossed_s: Option<f64>,
    /// When the vehicle's front reached the route's point (`None`: it never did).
    pub(super) front_reached_s: Option<f64>,
    /// The vehicle drove on afterwards (or the run ended by time).
    pub(super) drove_on: bool,
}

/// The yield rule: no contact, the mover across the route before the vehicle's front got there
/// (and, where they conflict, out of the conflict area before the vehicle entered it), and the
/// vehicle drove on.
pub(super) fn yield_met(f: &YieldFacts) -> bool {
    let crossed_first = match (f.mover_crossed_s, f.front_reached_s) {
        (Some(mover), Some(front)) => mover < front,
        (Some(_), None) => true,
        (None, _) => false,
    };
    let conflict_first = f
        .encroachment
        .is_none_or(|e| e.mover_first == Some(true) && e.pet_s > 0.0);
    !f.contact && f.drove_on && crossed_first && conflict_first
}
