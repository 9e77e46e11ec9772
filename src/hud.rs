//! A text overlay in the top-left corner; examples write its lines every frame.

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
            .add_systems(PostUpdate, show);
    }
}

fn spawn(mut commands: Commands) {
    commands.spawn((
        HudText,
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
