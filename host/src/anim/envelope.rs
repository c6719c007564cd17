//! The envelope of real motion capture an animation must stay within (issue 29's goals). Of
//! the 21 real takes `cargo xtask setup` fetches, 10 sit within it, every person walking,
//! dancing or kneeling but one just out; the rest leave it by pivoting or sliding feet, floor
//! work and acrobatics (`figurine check --reference`).

/// Deepest foot penetration, mm.
pub const PENETRATION_MM: f32 = 20.0;
/// Longest time with no foot near the ground, s: a jump's flight (DeepMimic's standing
/// long jump 0.38 s, its backflip 0.44 s).
pub const AIRBORNE_S: f32 = 0.5;
/// Median speed of a foot in contact, cm/s.
pub const SKATE_CM_S: f32 = 10.0;
/// A knee or an elbow bent backwards, °.
pub const BENT_BACKWARDS_DEG: f32 = 15.0;
/// Root speed, m/s: the fastest real take fetched (DeepMimic's run, 4.2 m/s).
pub const ROOT_SPEED_M_S: f32 = 4.2;
/// Root acceleration around a join of an assembled animation, m/s²: the largest 95th
/// percentile of the root's acceleration among the real takes within the rest of the envelope
/// (DeepMimic's kick, 28 m/s²; people walking 4–10, dancing 13). A join may move the root as
/// sharply as a kick does, no more.
pub const ROOT_ACCEL_JOIN_M_S2: f32 = 28.0;
/// Torso tilt, °: how far a frame's tilt may differ from its source frame's, and how far an
/// action's tilt (95th percentile, max) may lie outside the range of the real takes of its
/// kind ([`super::tilt_reference`]): the widest spread among one performer's takes of one
/// kind at different vigour (LAFAN1's dance, calm 16° to wild 28° at the 95th percentile;
/// its walks 5–13°).
pub const TILT_MARGIN_DEG: f32 = 11.6;
