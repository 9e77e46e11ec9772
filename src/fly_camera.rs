//! A fly camera: WASD or arrows to move, Q / E down and up, Shift for speed, hold the right
//! mouse button to look around, the wheel to change speed.

use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::prelude::*;

/// Put on a camera to fly it.
#[derive(Component, Debug, Clone)]
pub struct FlyCamera {
    /// Units per second.
    pub speed: f32,
    /// Radians per pixel of mouse motion.
    pub sensitivity: f32,
    /// Heading (radians about +y).
    pub yaw: f32,
    /// Pitch (radians, negative looks down).
    pub pitch: f32,
    /// Whether the mouse looks (right button) and the wheel sets the speed; off while the
    /// mouse does something else (a brush).
    pub mouse: bool,
}

impl Default for FlyCamera {
    fn default() -> Self {
        Self {
            speed: 30.0,
            sensitivity: 0.003,
            yaw: 0.0,
            pitch: -0.2,
            mouse: true,
        }
    }
}

impl FlyCamera {
    /// The camera's rotation for its yaw and pitch.
    pub fn rotation(&self) -> Quat {
        Quat::from_euler(EulerRot::YXZ, self.yaw, self.pitch, 0.0)
    }

    /// Puts the camera at `from`, looking at `target` (its yaw and pitch, and `transform`).
    pub fn place(&mut self, transform: &mut Transform, from: Vec3, target: Vec3) {
        let look = (target - from).normalize_or(Vec3::NEG_Z);
        self.yaw = (-look.x).atan2(-look.z);
        self.pitch = look.y.asin();
        transform.translation = from;
        transform.rotation = self.rotation();
    }
}

/// Moves [`FlyCamera`]s from keyboard and mouse input.
pub struct FlyCameraPlugin;

impl Plugin for FlyCameraPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(Update, fly);
    }
}

fn fly(
    time: Res<Time>,
    keys: Res<ButtonInput<KeyCode>>,
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    mut cameras: Query<(&mut FlyCamera, &mut Transform)>,
) {
    for (mut cam, mut transform) in &mut cameras {
        if cam.mouse && buttons.pressed(MouseButton::Right) {
            cam.yaw -= motion.delta.x * cam.sensitivity;
            cam.pitch = (cam.pitch - motion.delta.y * cam.sensitivity).clamp(-1.5, 1.5);
        }
        if cam.mouse && scroll.delta.y != 0.0 {
            cam.speed = (cam.speed * 1.2f32.powf(scroll.delta.y)).clamp(1.0, 2000.0);
        }
        transform.rotation = cam.rotation();
        let axis = |plus: [KeyCode; 2], minus: [KeyCode; 2]| {
            keys.any_pressed(plus) as i32 as f32 - keys.any_pressed(minus) as i32 as f32
        };
        let forward = axis(
            [KeyCode::KeyW, KeyCode::ArrowUp],
            [KeyCode::KeyS, KeyCode::ArrowDown],
        );
        let right = axis(
            [KeyCode::KeyD, KeyCode::ArrowRight],
            [KeyCode::KeyA, KeyCode::ArrowLeft],
        );
        let up = axis(
            [KeyCode::KeyE, KeyCode::Space],
            [KeyCode::KeyQ, KeyCode::KeyC],
        );
        let boost = if keys.pressed(KeyCode::ShiftLeft) {
            5.0
        } else {
            1.0
        };
        let step = (transform.forward() * forward + transform.right() * right + Vec3::Y * up)
            .normalize_or_zero()
            * cam.speed
            * boost
            * time.delta_secs();
        transform.translation += step;
    }
}
