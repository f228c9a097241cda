//! A feature node's control point ([`Cp`]) and the units of its angle and
//! profiles: what [`crate::patch::place::candidates`] extracts and [`crate::patch::place::costs`]
//! compares. It is its own module so that neither of those two depends on
//! the other for these definitions.

/// Angle units per turn (control-point angles are `u16`).
pub const TURN: i32 = 65536;

/// Samples along the path from the centre to a control point.
pub const ALONG: usize = 8;
/// Samples across the path at a control point.
pub const ACROSS: usize = 7;
/// Profile value of one prominence.
pub const UNIT: f32 = 64.0;

/// A control point with its profiles, normalised to the node's prominence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cp {
    pub pos: [f32; 2],
    /// Direction from the centre, `TURN` units per turn (0 = +x, +y is down).
    pub angle: u16,
    pub along: [i16; ALONG],
    pub across: [i16; ACROSS],
}
