//! The window viewer's state machine, free of any window: playback clock (play/pause, scrub,
//! speed, loop), orbit camera steering and follow mode, driven by abstract inputs. The winit
//! window ([`super::viewer`]) only translates its events into [`ViewerInput`]s.

use glam::Vec3;

use super::camera::{framing_distance, Camera, OrbitCamera};

/// Slowest playback speed factor.
pub const MIN_SPEED: f32 = 1.0 / 16.0;
/// Fastest playback speed factor.
pub const MAX_SPEED: f32 = 8.0;
/// Orbit radians per pixel of mouse drag.
const ORBIT_PER_PIXEL: f32 = 0.008;
/// Zoom factor per scroll line.
const ZOOM_PER_LINE: f32 = 1.12;

/// A playback clock over a clip of known duration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Playback {
    /// Current time, seconds.
    pub time: f32,
    /// Clip duration, seconds.
    pub duration: f32,
    /// Speed factor (1 = real time).
    pub speed: f32,
    /// Whether time advances.
    pub playing: bool,
    /// Whether playback wraps at the end (else it stops there).
    pub looping: bool,
}

impl Playback {
    /// A playing, looping clock at real-time speed.
    pub fn new(duration: f32) -> Self {
        Playback {
            time: 0.0,
            duration: if duration.is_finite() {
                duration.max(0.0)
            } else {
                0.0
            },
            speed: 1.0,
            playing: true,
            looping: true,
        }
    }

    /// Advances by `dt` seconds of wall time (ignored when paused or not finite).
    pub fn advance(&mut self, dt: f32) {
        if !self.playing || !dt.is_finite() || dt <= 0.0 {
            return;
        }
        let t = self.time + dt * self.speed;
        if t > self.duration {
            if self.looping && self.duration > 0.0 {
                self.time = t.rem_euclid(self.duration);
            } else {
                self.time = self.duration;
                self.playing = false;
            }
        } else {
            self.time = t;
        }
    }

    /// Jumps to `t` seconds (clamped to the clip).
    pub fn seek(&mut self, t: f32) {
        if t.is_finite() {
            self.time = t.clamp(0.0, self.duration);
        }
    }

    /// Moves by `dt` seconds (clamped), e.g. one frame back or forward.
    pub fn scrub(&mut self, dt: f32) {
        self.seek(self.time + dt);
    }

    /// Multiplies the speed by `factor`, within [`MIN_SPEED`]..=[`MAX_SPEED`].
    pub fn scale_speed(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.speed = (self.speed * factor).clamp(MIN_SPEED, MAX_SPEED);
        }
    }

    /// Play/pause; playing from the very end restarts.
    pub fn toggle(&mut self) {
        if !self.playing && self.time >= self.duration {
            self.time = 0.0;
        }
        self.playing = !self.playing;
    }

    /// Short status text, e.g. `playing x1.00` or `paused x0.50`.
    pub fn status(&self) -> String {
        format!(
            "{} x{:.2}{}",
            if self.playing { "playing" } else { "paused" },
            self.speed,
            if self.looping { "" } else { " once" }
        )
    }
}

/// A key the viewer reacts to (independent of the windowing library).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewerKey {
    /// Play/pause (Space).
    PlayPause,
    /// One frame back (Left); with `big`, one second (Shift+Left).
    Back {
        /// Step a second instead of a frame.
        big: bool,
    },
    /// One frame forward (Right); with `big`, one second (Shift+Right).
    Forward {
        /// Step a second instead of a frame.
        big: bool,
    },
    /// Twice as fast (Up).
    Faster,
    /// Half as fast (Down).
    Slower,
    /// Back to the start (Home).
    Restart,
    /// Toggle the camera following the figure (F).
    ToggleFollow,
    /// Toggle looping (L).
    ToggleLoop,
    /// Reset the camera to the automatic framing (R).
    ResetCamera,
    /// Close the viewer (Escape, Q).
    Quit,
}

/// Mouse buttons the viewer uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DragButton {
    /// Orbit.
    Left,
    /// Pan.
    Right,
}

/// One input event, already translated from the window system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ViewerInput {
    /// A key press.
    Key(ViewerKey),
    /// Mouse moved by (dx, dy) pixels with a button held.
    Drag {
        /// Which button.
        button: DragButton,
        /// Horizontal motion, pixels (right positive).
        dx: f32,
        /// Vertical motion, pixels (down positive).
        dy: f32,
    },
    /// Scroll wheel, lines (positive = away from the user = zoom in).
    Scroll(f32),
    /// Click on the timeline bar at a fraction (0..1) of its length.
    SeekFraction(f32),
}

/// Everything the viewer remembers between frames.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewerState {
    /// The playback clock.
    pub playback: Playback,
    /// The user's camera; in follow mode its target is an offset from the followed point.
    pub orbit: OrbitCamera,
    /// Whether the camera target tracks the figure.
    pub follow: bool,
    /// Seconds per frame of the source, for single-frame steps.
    pub frame_time: f32,
    /// Set when the user asked to quit.
    pub quit: bool,
    home: OrbitCamera,
    /// The followed point at the last [`ViewerState::camera`] call (world).
    last_followed: Vec3,
}

impl ViewerState {
    /// A viewer for a clip of `duration` seconds at `fps`, starting with the automatic framing:
    /// looking along `direction` (target → eye) at a sphere of `radius`, in a viewport of
    /// `aspect` = width / height.
    pub fn new(duration: f32, fps: f32, direction: Vec3, radius: f32, aspect: f32) -> Self {
        let home = OrbitCamera::from_direction(
            Vec3::ZERO,
            direction,
            framing_distance(radius.max(1e-3), aspect),
        );
        ViewerState {
            playback: Playback::new(duration),
            orbit: home,
            follow: true,
            frame_time: if fps.is_finite() && fps > 0.0 {
                1.0 / fps
            } else {
                1.0 / 30.0
            },
            quit: false,
            home,
            last_followed: Vec3::ZERO,
        }
    }

    /// Applies one input.
    pub fn handle(&mut self, input: ViewerInput) {
        match input {
            ViewerInput::Key(k) => match k {
                ViewerKey::PlayPause => self.playback.toggle(),
                ViewerKey::Back { big } => {
                    self.playback.playing = false;
                    self.playback
                        .scrub(if big { -1.0 } else { -self.frame_time });
                }
                ViewerKey::Forward { big } => {
                    self.playback.playing = false;
                    self.playback.scrub(if big { 1.0 } else { self.frame_time });
                }
                ViewerKey::Faster => self.playback.scale_speed(2.0),
                ViewerKey::Slower => self.playback.scale_speed(0.5),
                ViewerKey::Restart => self.playback.seek(0.0),
                ViewerKey::ToggleFollow => {
                    // Keep the view where it is: offset <-> absolute target.
                    if self.follow {
                        self.orbit.target += self.last_followed;
                    } else {
                        self.orbit.target = Vec3::ZERO;
                    }
                    self.follow = !self.follow;
                }
                ViewerKey::ToggleLoop => self.playback.looping = !self.playback.looping,
                ViewerKey::ResetCamera => {
                    self.orbit = self.home;
                    self.follow = true;
                }
                ViewerKey::Quit => self.quit = true,
            },
            ViewerInput::Drag { button, dx, dy } => match button {
                DragButton::Left => self
                    .orbit
                    .orbit(-dx * ORBIT_PER_PIXEL, dy * ORBIT_PER_PIXEL),
                DragButton::Right => self.orbit.pan(-dx * 0.0015, dy * 0.0015),
            },
            ViewerInput::Scroll(lines) => {
                if lines.is_finite() {
                    self.orbit.zoom(ZOOM_PER_LINE.powf(-lines));
                }
            }
            ViewerInput::SeekFraction(f) => {
                if f.is_finite() {
                    self.playback
                        .seek(f.clamp(0.0, 1.0) * self.playback.duration);
                }
            }
        }
    }

    /// The camera, given the point the figure is at now (`followed`) and the scene radius
    /// (for clip planes). In follow mode the orbit target is an offset from `followed`;
    /// in free mode it is absolute (leaving follow mode keeps the view where it was).
    pub fn camera(&mut self, followed: Vec3, radius: f32) -> Camera {
        let mut orbit = self.orbit;
        if self.follow && followed.is_finite() {
            self.last_followed = followed;
            orbit.target += followed;
        }
        orbit.camera(radius)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> ViewerState {
        ViewerState::new(10.0, 30.0, Vec3::new(0.5, 0.2, 1.0), 1.0, 16.0 / 9.0)
    }

    #[test]
    fn playback_loops_and_stops() {
        let mut p = Playback::new(2.0);
        p.advance(2.5);
        assert!((p.time - 0.5).abs() < 1e-6 && p.playing);
        p.looping = false;
        p.advance(5.0);
        assert_eq!(p.time, 2.0);
        assert!(!p.playing);
        p.toggle();
        assert_eq!(p.time, 0.0);
        assert!(p.playing);
        p.advance(f32::NAN);
        p.advance(-1.0);
        assert_eq!(p.time, 0.0);
    }

    #[test]
    fn speed_is_clamped() {
        let mut p = Playback::new(1.0);
        for _ in 0..10 {
            p.scale_speed(2.0);
        }
        assert_eq!(p.speed, MAX_SPEED);
        for _ in 0..20 {
            p.scale_speed(0.5);
        }
        assert_eq!(p.speed, MIN_SPEED);
        p.speed = 0.5;
        p.advance(1.0);
        assert!((p.time - 0.5).abs() < 1e-6);
    }

    #[test]
    fn keys_scrub_pause_and_seek() {
        let mut s = state();
        s.handle(ViewerInput::Key(ViewerKey::Forward { big: false }));
        assert!(!s.playback.playing);
        assert!((s.playback.time - 1.0 / 30.0).abs() < 1e-6);
        s.handle(ViewerInput::Key(ViewerKey::Forward { big: true }));
        s.handle(ViewerInput::Key(ViewerKey::Back { big: false }));
        assert!((s.playback.time - 1.0).abs() < 1e-5);
        s.handle(ViewerInput::Key(ViewerKey::Back { big: true }));
        s.handle(ViewerInput::Key(ViewerKey::Back { big: true }));
        assert_eq!(s.playback.time, 0.0);
        s.handle(ViewerInput::SeekFraction(0.25));
        assert!((s.playback.time - 2.5).abs() < 1e-5);
        s.handle(ViewerInput::Key(ViewerKey::Restart));
        assert_eq!(s.playback.time, 0.0);
        s.handle(ViewerInput::Key(ViewerKey::Quit));
        assert!(s.quit);
    }

    #[test]
    fn camera_follows_orbits_zooms_and_resets() {
        let mut s = state();
        let c0 = s.camera(Vec3::new(5.0, 1.0, 0.0), 1.0);
        assert_eq!(c0.target, Vec3::new(5.0, 1.0, 0.0));
        let d0 = (c0.eye - c0.target).length();
        s.handle(ViewerInput::Scroll(3.0));
        let d1 = (s.camera(Vec3::ZERO, 1.0).eye).length();
        assert!(d1 < d0, "scrolling forward zooms in");
        let az = s.orbit.azimuth;
        s.handle(ViewerInput::Drag {
            button: DragButton::Left,
            dx: 50.0,
            dy: 0.0,
        });
        assert!((s.orbit.azimuth - az).abs() > 0.1);
        // Leaving follow mode freezes the target where the figure was.
        let before = s.camera(Vec3::new(2.0, 0.0, 0.0), 1.0).target;
        s.handle(ViewerInput::Key(ViewerKey::ToggleFollow));
        let frozen = s.camera(Vec3::new(2.0, 0.0, 0.0), 1.0).target;
        assert_eq!(before, frozen);
        let later = s.camera(Vec3::new(9.0, 0.0, 0.0), 1.0).target;
        assert_eq!(frozen, later);
        s.handle(ViewerInput::Key(ViewerKey::ResetCamera));
        assert!(s.follow);
        let c = s.camera(Vec3::ZERO, 1.0);
        assert!(((c.eye - c.target).length() - d0).abs() < 1e-3);
    }
}
