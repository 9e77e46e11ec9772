//! A text overlay in the top-left corner; examples write its lines every frame. F1 hides
//! and shows it; `RWT_HUD=off` starts it hidden (clean screenshots).

use bevy::prelude::*;

/// The HUD's lines; examples overwrite them, [`HudPlugin`] shows them.
#[derive(Resource, Default, Debug, Clone)]
pub struct Hud {
    /// One entry a line.
    pub lines: Vec<String>,
}

#[derive(Component)]
struct HudText;

/// Spawns the overlay and keeps it in sync with [`Hud`].
pub struct HudPlugin;

impl Plugin for HudPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Hud>()
            .add_systems(Startup, spawn)
            .add_systems(PostUpdate, (toggle, show).chain());
    }
}

/// Whether the environment asks for the overlay hidden (`RWT_HUD=off`).
pub fn hidden_by_env() -> bool {
    std::env::var("RWT_HUD").is_ok_and(|v| v == "off" || v == "0")
}

fn spawn(mut commands: Commands) {
    let visibility = match hidden_by_env() {
        true => Visibility::Hidden,
        false => Visibility::Inherited,
    };
    commands.spawn((
        HudText,
        visibility,
        Text::new(""),
        TextFont::from_font_size(15.0),
        TextColor(Color::WHITE),
        Node {
            position_type: PositionType::Absolute,
            top: Val::Px(8.0),
            left: Val::Px(10.0),
            padding: UiRect::all(Val::Px(6.0)),
            ..default()
        },
        // Dark behind white text over any scene, light or dark: Bevy blends in linear
        // light, where a half-transparent black over white still reads as mid-grey; at
        // 95 % the panel stays darker than 0.1 linear (contrast with white above 7:1).
        BackgroundColor(Color::srgba(0.0, 0.0, 0.0, 0.95)),
    ));
}

/// F1 hides or shows the overlay.
fn toggle(
    keys: Option<Res<ButtonInput<KeyCode>>>,
    mut text: Query<&mut Visibility, With<HudText>>,
) {
    if !keys.is_some_and(|k| k.just_pressed(KeyCode::F1)) {
        return;
    }
    for mut visibility in &mut text {
        *visibility = match *visibility {
            Visibility::Hidden => Visibility::Inherited,
            _ => Visibility::Hidden,
        };
    }
}

fn show(hud: Res<Hud>, mut text: Query<&mut Text, With<HudText>>) {
    if !hud.is_changed() {
        return;
    }
    let joined = hud.lines.join("\n");
    for mut t in &mut text {
        if t.0 != joined {
            t.0.clone_from(&joined);
        }
    }
}
