//! One return of a revolution as the classification pass leaves it ([`Classified`]): what
//! `insert.rs` writes and reads, and `open_top.rs` completes with each obstacle return's open top.
//! In a file of its own so that neither of the two names the other for it.

/// One return, classified once for every level.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Classified {
    /// Cell index in the window, `u32::MAX` when dropped.
    pub(super) cell: u32,
    pub(super) height_m: f32,
    pub(super) range_xy_m: f32,
    pub(super) obstacle: bool,
    /// An obstacle return's open top: how high above the ground its object may reach where the
    /// sensor cannot see, metres (`open_top.rs`; `NO_CLAIM` when the return above claims).
    pub(super) open_top_m: f32,
}

pub(super) const DROPPED: u32 = u32::MAX;
