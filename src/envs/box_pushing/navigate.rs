//! Move-to-waypoint: the reference's one-step greedy planner (`docs/BOX_PUSHING.md` §5.1).

use super::geometry::{Cell, Heading};
use super::state::{Boxes, Robot};

/// Turn cost of heading to `d` from `h`, as a rank: 0 straight on, 1 to the side (cost 0.1),
/// 2 behind (cost 0.2). Distances are integers and costs are below 1, so comparing
/// `(distance, rank)` lexicographically equals the reference's float score (`docs/BOX_PUSHING.md` §5.1 (b)).
#[inline]
fn turn_rank(h: Heading, d: Heading) -> i32 {
    if d == h {
        0
    } else if d == h.behind() {
        2
    } else {
        1
    }
}

/// The direction the planner picks from `robot` towards `target`: the unblocked neighbour with the
/// lowest (Manhattan distance, turn rank), ties to the lowest direction index. If every neighbour
/// were blocked the reference's argmin over infinities returns north; that cannot happen (the four
/// neighbours span three rows and only one row blocks), but north is kept for the record.
#[inline]
fn choose_direction(robot: &Robot, target: Cell, boxes: &Boxes) -> Heading {
    let mut best = Heading::North;
    let mut best_key = i32::MAX;
    for d in Heading::ALL {
        let next = robot.cell.step(d);
        if boxes.blocks_navigation(next) {
            continue;
        }
        // rank < 4, so distance * 4 + rank orders as the pair (distance, rank).
        let key = next.manhattan(target) * 4 + turn_rank(robot.heading, d);
        if key < best_key {
            best_key = key;
            best = d;
        }
    }
    best
}

/// One primitive step of Move-to-waypoint `k` whose cell is `target` (`docs/BOX_PUSHING.md` §5.1). Sets
/// `robot.finished` and the remembered waypoint on arrival facing north. Never moves boxes and
/// never gives rewards.
#[inline]
pub fn move_step(robot: &mut Robot, k: u8, target: Cell, boxes: &Boxes) {
    // (a) Already there: snap north in one step, whatever the heading (quirk Q6).
    if robot.cell == target {
        robot.heading = Heading::North;
        robot.waypoint = Some(k);
        robot.finished = true;
        return;
    }
    // (b) One move or one turn towards the best neighbour.
    let d = choose_direction(robot, target, boxes);
    match turn_rank(robot.heading, d) {
        0 => robot.cell = robot.cell.step(d),
        // Behind: one clockwise quarter-turn, not a turn towards d (quirk Q7).
        2 => robot.heading = robot.heading.right(),
        _ => robot.heading = d,
    }
    // (c) Arrival counts only when facing north; otherwise the next step snaps (a).
    if robot.cell == target && robot.heading == Heading::North {
        robot.waypoint = Some(k);
        robot.finished = true;
    }
}

#[cfg(test)]
mod tests {
    use super::super::layout::GridLayout;
    use super::*;

    fn boxes(l: &GridLayout) -> Boxes {
        Boxes {
            small: l.small_boxes,
            big_left: l.big_box_left,
        }
    }

    /// Steps until finished, with a cap.
    fn travel(robot: &mut Robot, k: u8, l: &GridLayout, cap: usize) -> Option<usize> {
        let b = boxes(l);
        robot.finished = false;
        for s in 1..=cap {
            move_step(robot, k, l.waypoints[k as usize], &b);
            if robot.finished {
                return Some(s);
            }
        }
        None
    }

    #[test]
    fn travel_times_from_the_start_match_the_spec_table() {
        // `docs/BOX_PUSHING.md` §5.1: robot 0 to W0..W3 takes N/2-1, 3N/2-4, N-3, N-2 steps; robot 1 mirrored.
        for n in [8, 10, 12, 30] {
            let l = GridLayout::new(n);
            let r0 = [n / 2 - 1, 3 * n / 2 - 4, n - 3, n - 2];
            let r1 = [3 * n / 2 - 4, n / 2 - 1, n - 2, n - 3];
            for k in 0..4u8 {
                for (robot, expected) in [(0usize, r0), (1, r1)] {
                    let (cell, heading) = l.robot_starts[robot];
                    let mut r = Robot::at_start(cell, heading);
                    let got = travel(&mut r, k, &l, 1000);
                    assert_eq!(
                        got,
                        Some(expected[k as usize] as usize),
                        "n={n} robot {robot} W{k}"
                    );
                    assert_eq!(r.cell, l.waypoints[k as usize]);
                    assert_eq!(r.heading, Heading::North);
                    assert_eq!(r.waypoint, Some(k));
                }
            }
        }
    }

    #[test]
    fn robot_zero_to_w2_moves_east_three_times_turns_then_goes_north() {
        // `docs/BOX_PUSHING.md` §5.1 example on 10x10.
        let l = GridLayout::new(10);
        let b = boxes(&l);
        let mut r = Robot::at_start(Cell::new(1, 1), Heading::East);
        r.finished = false;
        let mut path = Vec::new();
        for _ in 0..7 {
            move_step(&mut r, 2, l.waypoints[2], &b);
            path.push((r.cell, r.heading, r.finished));
        }
        let e = Heading::East;
        let n = Heading::North;
        assert_eq!(
            path,
            vec![
                (Cell::new(2, 1), e, false),
                (Cell::new(3, 1), e, false),
                (Cell::new(4, 1), e, false),
                (Cell::new(4, 1), n, false),
                (Cell::new(4, 2), n, false),
                (Cell::new(4, 3), n, false),
                (Cell::new(4, 4), n, true),
            ]
        );
    }

    #[test]
    fn detour_around_small_box_one_takes_fourteen_steps() {
        // `docs/BOX_PUSHING.md` §5.1 detour example (scenario S14's last leg): from (9,9) facing north to W1.
        let l = GridLayout::new(10);
        let b = boxes(&l);
        let mut r = Robot::at_start(Cell::new(9, 9), Heading::North);
        r.finished = false;
        let mut trace = Vec::new();
        for _ in 0..14 {
            move_step(&mut r, 1, l.waypoints[1], &b);
            trace.push((r.cell.col, r.cell.row, r.heading.arrow(), r.finished));
        }
        let expected = vec![
            (9, 9, '<', false), // turn west
            (8, 9, '<', false), // move
            (8, 9, 'v', false), // turn south
            (8, 8, 'v', false),
            (8, 7, 'v', false),
            (8, 6, 'v', false),
            (8, 6, '>', false), // south blocked; east and west tie, east has the lower index
            (9, 6, '>', false),
            (9, 6, 'v', false),
            (9, 5, 'v', false),
            (9, 4, 'v', false),
            (9, 4, '<', false),
            (8, 4, '<', false), // arrives facing west: still busy
            (8, 4, '^', true),  // snap north
        ];
        assert_eq!(trace, expected);
    }

    #[test]
    fn behind_choice_turns_clockwise_not_towards_the_goal() {
        // Quirk Q7: facing east with the target straight west, the robot turns to south.
        let l = GridLayout::new(10);
        let b = boxes(&l);
        let mut r = Robot::at_start(Cell::new(6, 4), Heading::East);
        r.finished = false;
        move_step(&mut r, 2, l.waypoints[2], &b);
        assert_eq!((r.cell, r.heading), (Cell::new(6, 4), Heading::South));
    }

    #[test]
    fn on_the_waypoint_any_heading_snaps_north_in_one_step() {
        let l = GridLayout::new(10);
        let b = boxes(&l);
        let mut r = Robot::at_start(l.waypoints[3], Heading::South);
        r.finished = false;
        move_step(&mut r, 3, l.waypoints[3], &b);
        assert_eq!(r.heading, Heading::North);
        assert!(r.finished);
        assert_eq!(r.waypoint, Some(3));
    }

    #[test]
    fn every_free_cell_and_heading_reaches_every_waypoint() {
        // `docs/BOX_PUSHING.md` §5.1: exhaustive for N = 10 and 30, worst case 14 steps over the Manhattan distance.
        let mut worst = 0;
        for n in [10, 30] {
            let l = GridLayout::new(n);
            let b = boxes(&l);
            for col in 0..n {
                for row in 0..n {
                    let cell = Cell::new(col, row);
                    if (0..3).any(|k| b.box_covers(k, cell)) {
                        continue;
                    }
                    for h in Heading::ALL {
                        for k in 0..4u8 {
                            let mut r = Robot::at_start(cell, h);
                            let steps = travel(&mut r, k, &l, 4 * n as usize + 40)
                                .unwrap_or_else(|| panic!("n={n} {cell:?} {h:?} W{k} livelocks"));
                            let extra = steps as i32 - cell.manhattan(l.waypoints[k as usize]);
                            worst = worst.max(extra);
                        }
                    }
                }
            }
        }
        assert_eq!(worst, 14);
    }
}
