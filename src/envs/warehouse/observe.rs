//! Macro-observations (`docs/WAREHOUSE.md` §7): what each agent sees when its macro-action finishes.
//!
//! Turtlebot (13): location one-hot [workshop, tool-room wait, table, none] | human work step
//! one-hot (only at the workshop) | basket counts | Fetch's `ready` (only away from the workshop).
//! Fetch (4): `ready` | Turtlebot 0 / 1 exactly on its table spot.

use super::fetch::Fetch;
use super::human::Human;
use super::turtlebot::Turtlebot;

/// Turtlebot observation size: 4 locations + 4 human steps + 3 tools + 2 ready bits.
pub const TB_OBS: usize = 13;
/// Fetch observation size: 2 ready bits + 2 beside-table bits.
pub const FETCH_OBS: usize = 4;

const LOC_AT: usize = 0;
const HUMAN_AT: usize = 4;
const BASKET_AT: usize = 8;
const READY_AT: usize = 11;
/// Index of the "none" location (no waypoint reached yet).
const LOC_NONE: usize = 3;

/// A Turtlebot's observation at reset: location none, everything else zero (`docs/WAREHOUSE.md` §7).
pub fn turtlebot_reset_obs() -> [f32; TB_OBS] {
    let mut o = [0.0; TB_OBS];
    o[LOC_AT + LOC_NONE] = 1.0;
    o
}

/// Write Turtlebot `tb`'s observation after a step where it finished (post-human-update state).
pub fn write_turtlebot_obs(out: &mut [f32; TB_OBS], tb: &Turtlebot, human: &Human, fetch: &Fetch) {
    *out = [0.0; TB_OBS];
    out[LOC_AT + tb.loc.unwrap_or(LOC_NONE)] = 1.0;
    if tb.loc == Some(0) {
        out[HUMAN_AT + human.step_k] = 1.0;
    }
    for (o, &b) in out[BASKET_AT..READY_AT].iter_mut().zip(&tb.basket) {
        *o = b as f32;
    }
    // The ready signal reaches only the tool room (codes 1, 2) and a robot that has not arrived
    // anywhere yet.
    if tb.loc != Some(0) {
        out[READY_AT] = fetch.ready[0] as f32;
        out[READY_AT + 1] = fetch.ready[1] as f32;
    }
}

/// Write the Fetch's observation after a step where it finished.
pub fn write_fetch_obs(out: &mut [f32; FETCH_OBS], fetch: &Fetch, tbs: &[Turtlebot; 2]) {
    out[0] = fetch.ready[0] as f32;
    out[1] = fetch.ready[1] as f32;
    out[2] = f32::from(u8::from(tbs[0].at_table()));
    out[3] = f32::from(u8::from(tbs[1].at_table()));
}

/// Element names of a Turtlebot observation, in layout order.
pub fn turtlebot_obs_names() -> Vec<String> {
    let mut names: Vec<String> = [
        "loc_workshop",
        "loc_tool_room_wait",
        "loc_table",
        "loc_none",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    names.extend((0..4).map(|k| format!("human_step_{k}")));
    names.extend((0..3).map(|t| format!("basket_tool_{t}")));
    names.extend(["ready_one_tool".to_string(), "ready_two_tools".to_string()]);
    names
}

/// Element names of the Fetch observation, in layout order.
pub fn fetch_obs_names() -> Vec<String> {
    [
        "ready_one_tool",
        "ready_two_tools",
        "t0_beside_table",
        "t1_beside_table",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn name_lists_match_the_sizes() {
        assert_eq!(turtlebot_obs_names().len(), TB_OBS);
        assert_eq!(fetch_obs_names().len(), FETCH_OBS);
        assert_eq!(turtlebot_obs_names()[LOC_NONE], "loc_none");
        assert_eq!(turtlebot_obs_names()[READY_AT], "ready_one_tool");
        assert_eq!(turtlebot_obs_names()[BASKET_AT + 2], "basket_tool_2");
    }

    #[test]
    fn reset_obs_is_location_none() {
        assert_eq!(
            turtlebot_reset_obs(),
            [0., 0., 0., 1., 0., 0., 0., 0., 0., 0., 0., 0., 0.]
        );
    }
}
