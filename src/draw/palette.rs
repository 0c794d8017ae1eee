//! The fixed colour table every frame is drawn with.
//!
//! One small palette shared by both domains keeps frames indexed (one byte per pixel) and lets the
//! GIF use a single global colour table, which is what keeps rollout files small.

/// A palette entry. The discriminant is the pixel value stored in a [`super::Canvas`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Colour {
    /// Floor of both domains.
    Background,
    /// Box Pushing cell borders; human work steps not yet reached.
    GridLine,
    /// Outlines, walls, heading markers and text.
    Dark,
    /// Labels drawn on coloured fills (Warehouse: the Fetch's `F`, the Turtlebots' digits).
    White,
    /// Box Pushing goal row (the paper's yellow bar).
    Goal,
    /// Box Pushing waypoints, drawn faintly.
    Waypoint,
    /// Box Pushing small boxes.
    SmallBox,
    /// Box Pushing big box.
    BigBox,
    /// Box Pushing robot 0 and Turtlebot 0 (the paper's green T-0).
    Agent0,
    /// Box Pushing robot 1 and Turtlebot 1 (the paper's blue T-1).
    Agent1,
    /// The Fetch (the paper's gray robot).
    Fetch,
    /// Warehouse tables and empty staging slots.
    Table,
    /// Warehouse waypoints (red dots as in the reference's renderer); a human waiting for a tool.
    Red,
    /// Warehouse humans; Overcooked onions.
    Human,
    /// Tool 0, 1, 2 of the Warehouse, wherever they are (staging area, basket, human's request).
    Tool0,
    /// See [`Colour::Tool0`].
    Tool1,
    /// See [`Colour::Tool0`].
    Tool2,
    /// Workshop floor.
    Workshop,
    /// The human's current work step while the step's time runs.
    Working,
    /// Status bar background.
    HudBackground,
    /// A third robot: MacroMARL's Turtlebot 2 and Overcooked's third cook.
    Agent2,
}

impl Colour {
    /// Every colour in discriminant order.
    pub const ALL: [Colour; 21] = [
        Colour::Background,
        Colour::GridLine,
        Colour::Dark,
        Colour::White,
        Colour::Goal,
        Colour::Waypoint,
        Colour::SmallBox,
        Colour::BigBox,
        Colour::Agent0,
        Colour::Agent1,
        Colour::Fetch,
        Colour::Table,
        Colour::Red,
        Colour::Human,
        Colour::Tool0,
        Colour::Tool1,
        Colour::Tool2,
        Colour::Workshop,
        Colour::Working,
        Colour::HudBackground,
        Colour::Agent2,
    ];

    /// The colour stored as pixel value `index`, if any.
    pub fn from_index(index: u8) -> Option<Colour> {
        Self::ALL.get(usize::from(index)).copied()
    }

    /// sRGB of this colour.
    pub fn rgb(self) -> [u8; 3] {
        match self {
            Colour::Background => [250, 250, 247],
            Colour::GridLine => [205, 205, 205],
            Colour::Dark => [35, 35, 40],
            Colour::White => [255, 255, 255],
            Colour::Goal => [245, 205, 40],
            Colour::Waypoint => [222, 222, 240],
            Colour::SmallBox => [214, 150, 70],
            Colour::BigBox => [140, 85, 35],
            Colour::Agent0 => [30, 150, 60],
            Colour::Agent1 => [40, 90, 210],
            Colour::Fetch => [135, 135, 135],
            Colour::Table => [170, 110, 20],
            Colour::Red => [190, 35, 35],
            Colour::Human => [150, 70, 160],
            Colour::Tool0 => [225, 45, 140],
            Colour::Tool1 => [245, 150, 0],
            Colour::Tool2 => [0, 170, 200],
            Colour::Workshop => [232, 239, 250],
            Colour::Working => [80, 205, 80],
            Colour::HudBackground => [236, 236, 236],
            Colour::Agent2 => [150, 140, 10],
        }
    }

    /// The colour of Warehouse tool `k` (0..3); tools beyond the paper's three reuse the cycle.
    pub fn tool(k: usize) -> Colour {
        [Colour::Tool0, Colour::Tool1, Colour::Tool2][k % 3]
    }

    /// The colour of the `i`-th of several robots of one kind (MacroMARL's Turtlebots, the
    /// cooks of Overcooked): green, blue, then olive for the third and any further one.
    pub fn robot(i: usize) -> Colour {
        match i {
            0 => Colour::Agent0,
            1 => Colour::Agent1,
            _ => Colour::Agent2,
        }
    }

    /// The colour of agent `i`'s robot (Box Pushing robots, Turtlebots; the Fetch is agent 2).
    pub fn agent(i: usize) -> Colour {
        match i {
            0 => Colour::Agent0,
            1 => Colour::Agent1,
            _ => Colour::Fetch,
        }
    }
}

/// The pixel value GIF frames after the first use for "unchanged since the previous frame"; it is
/// never drawn, only written by the encoder.
pub const TRANSPARENT: u8 = Colour::ALL.len() as u8;

/// The GIF colour table: every colour in index order, then the (never displayed) transparent slot.
pub fn gif_palette() -> Vec<u8> {
    let mut rgb: Vec<u8> = Colour::ALL.iter().flat_map(|c| c.rgb()).collect();
    rgb.extend_from_slice(&[255, 0, 255]);
    rgb
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_round_trip_and_transparent_is_outside_the_colours() {
        for (i, c) in Colour::ALL.iter().enumerate() {
            assert_eq!(*c as usize, i);
            assert_eq!(Colour::from_index(i as u8), Some(*c));
        }
        assert_eq!(Colour::from_index(TRANSPARENT), None);
        assert_eq!(gif_palette().len(), 3 * (Colour::ALL.len() + 1));
    }

    #[test]
    fn colours_are_distinct() {
        for (i, a) in Colour::ALL.iter().enumerate() {
            for b in &Colour::ALL[i + 1..] {
                assert_ne!(a.rgb(), b.rgb(), "{a:?} and {b:?}");
            }
        }
    }
}
