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
