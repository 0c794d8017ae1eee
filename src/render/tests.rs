//! Whole-episode checks: record, encode, decode, compare.

use std::fs::File;
use std::path::Path;

use rand::{Rng, SeedableRng};

use super::*;
use crate::envs::box_pushing::actions::PUSH;
use crate::envs::box_pushing::draw as box_pushing;
use crate::envs::box_pushing::geometry::Cell;
use crate::envs::warehouse::draw as warehouse;
use crate::envs::{AnyEnv, EnvRng, MacroEnv};

/// A decoded GIF: logical size, every frame composited onto the previous one, and delays (cs).
struct Decoded {
    width: usize,
    height: usize,
    screens: Vec<Vec<u8>>,
    delays: Vec<u16>,
}

fn decode(path: &Path) -> Decoded {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = opts.read_info(File::open(path).unwrap()).unwrap();
    let (width, height) = (usize::from(dec.width()), usize::from(dec.height()));
    let mut screen = vec![0u8; width * height];
    let (mut screens, mut delays) = (Vec::new(), Vec::new());
    while let Some(f) = dec.read_next_frame().unwrap() {
        let (l, t, w) = (
            usize::from(f.left),
            usize::from(f.top),
            usize::from(f.width),
        );
        for (i, &p) in f.buffer.iter().enumerate() {
            if Some(p) != f.transparent {
                screen[(t + i / w) * width + l + i % w] = p;
            }
        }
        screens.push(screen.clone());
        delays.push(f.delay);
    }
    Decoded {
        width,
        height,
        screens,
        delays,
    }
}

/// The spec's optimal joint policy (box_pushing.md section 11): robot 0 to W2, robot 1 to W3,
/// then both push.
fn bp_optimal(env: &AnyEnv, actions: &mut [usize]) {
    let AnyEnv::BoxPushing(bp) = env else {
        panic!("Box Pushing expected")
    };
    for (i, a) in actions.iter_mut().enumerate() {
        if env.is_free(i) {
            *a = if bp.robot(i).waypoint.is_some() {
                PUSH
            } else {
                2 + i
            };
        }
    }
}

fn bp10() -> AnyEnv {
    crate::envs::box_pushing::spec(10, 100).build().unwrap()
}

fn wtd() -> AnyEnv {
    crate::envs::warehouse::spec(150, 0.0).build().unwrap()
}

/// Warehouse scenario S2 (`docs/WAREHOUSE.md` §14): each free agent takes its queue's next action, then
/// Go-to-WS / Wait. Reaches the optimum 262 at step 38.
fn wtd_s2() -> impl FnMut(&AnyEnv, &mut [usize]) {
    let queues: [&[usize]; 3] = [&[2, 2, 0], &[2, 0, 2, 0], &[3, 2, 4, 1, 5, 2]];
    let mut next = [0usize; 3];
    move |env, actions| {
        for i in 0..3 {
            if env.is_free(i) {
                actions[i] = queues[i].get(next[i]).copied().unwrap_or(0);
                next[i] += 1;
            }
        }
    }
}

#[test]
fn bp10_optimal_episode_gives_twelve_frames_that_round_trip_through_the_gif() {
    let mut env = bp10();
    let mut rng = EnvRng::seed_from_u64(0);
    let frames = record_episode(&mut env, &mut rng, bp_optimal).unwrap();
    // T* = 11 steps (`docs/BOX_PUSHING.md` §11): reset frame plus one per step.
    assert_eq!(frames.len(), 12);
    assert_eq!(
        frames.iter().map(|f| f.t).collect::<Vec<_>>(),
        (0..12).collect::<Vec<_>>()
    );
    let last = frames.last().unwrap();
    assert!(
        (last.team_return - 98.9).abs() < 1e-9,
        "{}",
        last.team_return
    );
    assert!(last.hold && frames[..11].iter().all(|f| !f.hold));

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bp10.gif");
    write_gif(&frames, &path, 120).unwrap();
    let gif = decode(&path);
    assert_eq!((gif.width, gif.height), (321, frames[0].image.height()));
    assert_eq!(gif.screens.len(), 12);
    for (k, (screen, frame)) in gif.screens.iter().zip(&frames).enumerate() {
        assert!(
            screen == frame.image.pixels(),
            "decoded frame {k} differs from the drawn one"
        );
    }
    assert_eq!(gif.delays[0], 12);
    assert_eq!(gif.delays[11], (HOLD_MS / 10) as u16);
    let size = std::fs::metadata(&path).unwrap().len();
    assert!(size < 60_000, "GIF of 12 frames is {size} bytes");
    // No temp file is left beside it.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn bp10_last_frame_shows_the_big_box_in_the_goal_row_with_both_robots_below() {
    let mut env = bp10();
    let mut rng = EnvRng::seed_from_u64(0);
    let frames = record_episode(&mut env, &mut rng, bp_optimal).unwrap();
    let img = &frames.last().unwrap().image;
    let g = box_pushing::GridPixels::new(10);
    let px = |cell: Cell, dx: f64| {
        let (x, y) = g.centre(cell);
        img.pixel((x + dx) as usize, y as usize)
    };
    assert_eq!(px(Cell::new(4, 9), 0.0), Some(Colour::BigBox));
    assert_eq!(px(Cell::new(5, 9), 0.0), Some(Colour::BigBox));
    assert_eq!(
        px(Cell::new(4, 5), 0.0),
        Some(Colour::Background),
        "box has left row 5"
    );
    // Robots face north, so left of centre shows the body colour.
    assert_eq!(px(Cell::new(4, 8), -5.0), Some(Colour::Agent0));
    assert_eq!(px(Cell::new(5, 8), -5.0), Some(Colour::Agent1));
    assert_eq!(
        px(Cell::new(1, 5), 0.0),
        Some(Colour::SmallBox),
        "small boxes untouched"
    );
}

#[test]
fn bp30_frames_are_361_pixels_wide() {
    let mut env = crate::envs::box_pushing::spec(30, 200).build().unwrap();
    let mut rng = EnvRng::seed_from_u64(0);
    let frames = record_episode(&mut env, &mut rng, bp_optimal).unwrap();
    assert_eq!(
        frames.len(),
        42,
        "T* = 41 on 30x30 (`docs/BOX_PUSHING.md` §11)"
    );
    assert_eq!(frames[0].image.width(), 361);
}

#[test]
fn wtd_random_episode_runs_to_the_horizon_and_decodes() {
    let mut env = wtd();
    let mut rng = EnvRng::seed_from_u64(3);
    let mut policy_rng = EnvRng::seed_from_u64(4);
    let n_actions = env.n_actions().to_vec();
    let frames = record_episode(&mut env, &mut rng, |env, actions| {
        for i in 0..3 {
            if env.is_free(i) {
                actions[i] = policy_rng.gen_range(0..n_actions[i]);
            }
        }
    })
    .unwrap();
    let last = frames.last().unwrap();
    assert_eq!(frames.len(), last.t + 1);
    assert!(last.t <= 150);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wtd.gif");
    write_gif(&frames, &path, 100).unwrap();
    let gif = decode(&path);
    assert_eq!((gif.width, gif.height), (420, frames[0].image.height()));
    assert_eq!(gif.screens.len(), frames.len());
    assert!(gif.screens.last().unwrap() == last.image.pixels());
}

#[test]
fn wtd_scripted_optimum_ends_at_step_38_with_return_262() {
    let mut env = wtd();
    let mut rng = EnvRng::seed_from_u64(0);
    let frames = record_episode(&mut env, &mut rng, wtd_s2()).unwrap();
    assert_eq!(frames.len(), 39);
    assert_eq!(frames[38].team_return, 262.0);
    // Step 18 (`docs/WAREHOUSE.md` S2 events): Turtlebot 1 delivered tool 0 and the human moved on to work
    // step 1, so the first square of the work-step bar is dark.
    let img = &frames[18].image;
    let (bar_x, _) = warehouse::to_px([5.15, 0.0]);
    assert_eq!(img.pixel(bar_x as usize + 7, 13), Some(Colour::Dark));
    // Step 30: Turtlebot 1 waits at its table spot carrying tool 2 (cyan, drawn to its right);
    // Turtlebot 0 carries nothing.
    let img = &frames[30].image;
    let r = warehouse::TB_RADIUS_M * warehouse::PX_PER_M;
    let (x, y) = warehouse::to_px([1.2, 3.0]);
    let basket = |x: f64, y: f64| img.pixel(x as usize, y as usize);
    assert_eq!(basket(x + r + 5.0, y - r + 4.0), Some(Colour::Tool2));
    let (x0, y0) = warehouse::to_px([6.0, 3.0]);
    assert_eq!(basket(x0 - r - 5.0, y0 - r + 4.0), Some(Colour::Workshop));
}

#[test]
fn refused_action_is_reported_with_its_step() {
    let mut env = bp10();
    let mut rng = EnvRng::seed_from_u64(0);
    let err = record_episode(&mut env, &mut rng, |_, a| a.fill(8)).unwrap_err();
    assert!(matches!(err, RenderError::Env { t: 1, .. }), "{err}");
    assert!(err.to_string().contains("out of range"), "{err}");
}

#[test]
fn writing_no_frames_or_mixed_sizes_names_the_file() {
    let path = Path::new("/nonexistent/x.gif");
    let err = write_gif(&[], path, 100).unwrap_err();
    assert!(err.to_string().contains("/nonexistent/x.gif"), "{err}");
    let a = Frame::capture(&bp10(), 0.0).unwrap();
    let b = Frame::capture(&wtd(), 0.0).unwrap();
    let err = write_gif(&[a.clone(), b], path, 100).unwrap_err();
    assert!(
        matches!(err, RenderError::SizeMismatch { index: 1, .. }),
        "{err}"
    );
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, b"").unwrap();
    let err = write_gif(&[a], &blocker.join("x.gif"), 100).unwrap_err();
    assert!(matches!(err, RenderError::Io { .. }), "{err}");
    assert!(err.to_string().contains("x.gif"), "{err}");
}

#[test]
fn recording_is_deterministic() {
    let run = || {
        let mut env = wtd();
        let mut rng = EnvRng::seed_from_u64(0);
        record_episode(&mut env, &mut rng, wtd_s2()).unwrap()
    };
    assert_eq!(run(), run());
}

/// Write PNGs of a few frames and the scripted GIFs to `target/render-preview/` for a human to
/// look at: `cargo test --release render::tests::preview -- --ignored`.
#[test]
#[ignore]
fn preview() {
    use plotters::prelude::*;
    let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/render-preview");
    std::fs::create_dir_all(&out).unwrap();
    let png = |img: &Canvas, name: &str| {
        let path = out.join(name);
        let root = BitMapBackend::new(&path, (img.width() as u32, img.height() as u32))
            .into_drawing_area();
        for y in 0..img.height() {
            for x in 0..img.width() {
                let [r, g, b] = img.pixel(x, y).unwrap().rgb();
                root.draw_pixel((x as i32, y as i32), &RGBColor(r, g, b))
                    .unwrap();
            }
        }
        root.present().unwrap();
    };
    let mut rng = EnvRng::seed_from_u64(0);
    let mut env = bp10();
    let frames = record_episode(&mut env, &mut rng, bp_optimal).unwrap();
    png(&frames[0].image, "bp10_t0.png");
    png(&frames[8].image, "bp10_t8.png");
    write_gif(&frames, &out.join("bp10_optimal.gif"), 250).unwrap();
    let mut env = crate::envs::box_pushing::spec(30, 200).build().unwrap();
    let frames = record_episode(&mut env, &mut rng, bp_optimal).unwrap();
    png(&frames[30].image, "bp30_t30.png");
    write_gif(&frames, &out.join("bp30_optimal.gif"), 120).unwrap();
    let mut env = wtd();
    let frames = record_episode(&mut env, &mut rng, wtd_s2()).unwrap();
    for t in [0, 3, 8, 18, 30, 38] {
        png(&frames[t].image, &format!("wtd_t{t}.png"));
    }
    write_gif(&frames, &out.join("wtd_scripted.gif"), 200).unwrap();
}

/// Drawing and encoding speed and file sizes, for docs/PERFORMANCE.md:
/// `cargo test --release render::tests::speed -- --ignored --nocapture`.
#[test]
#[ignore]
fn speed() {
    use std::time::Instant;
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, AnyEnv); 3] = [
        ("bp10 optimal", bp10()),
        (
            "bp30 optimal",
            crate::envs::box_pushing::spec(30, 200).build().unwrap(),
        ),
        ("wtd random", wtd()),
    ];
    for (name, mut env) in cases {
        let mut rng = EnvRng::seed_from_u64(0);
        let mut policy_rng = EnvRng::seed_from_u64(1);
        let n_actions = env.n_actions().to_vec();
        let reps = 5;
        let start = Instant::now();
        let mut frames = Vec::new();
        for _ in 0..reps {
            frames = record_episode(&mut env, &mut rng, |env, actions| {
                if let AnyEnv::BoxPushing(_) = env {
                    bp_optimal(env, actions);
                } else {
                    for (i, a) in actions.iter_mut().enumerate() {
                        if env.is_free(i) {
                            *a = policy_rng.gen_range(0..n_actions[i]);
                        }
                    }
                }
            })
            .unwrap();
        }
        let record = start.elapsed().as_secs_f64() / reps as f64;
        let path = dir.path().join("x.gif");
        let start = Instant::now();
        for _ in 0..reps {
            write_gif(&frames, &path, 100).unwrap();
        }
        let encode = start.elapsed().as_secs_f64() / reps as f64;
        let size = std::fs::metadata(&path).unwrap().len();
        let img = &frames[0].image;
        println!(
            "{name}: {} frames of {}x{}: record {:.1} ms ({:.0} frames/s), write {:.1} ms, {} KiB",
            frames.len(),
            img.width(),
            img.height(),
            record * 1e3,
            frames.len() as f64 / record,
            encode * 1e3,
            size / 1024
        );
    }
}

/// A user's domain that draws: one agent walks a 4-cell corridor, drawn as a lit cell.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Walk {
    at: usize,
    t: usize,
}

impl MacroEnv for Walk {
    fn n_agents(&self) -> usize {
        1
    }
    fn obs_sizes(&self) -> &[usize] {
        &[1]
    }
    fn n_actions(&self) -> &[usize] {
        &[1]
    }
    fn action_names(&self, _: usize) -> &'static [&'static str] {
        &["step"]
    }
    fn obs_names(&self, _: usize) -> Vec<String> {
        vec!["x".into()]
    }
    fn horizon(&self) -> usize {
        3
    }
    fn reset(&mut self, _: &mut EnvRng) {
        (self.at, self.t) = (0, 0);
    }
    fn step(
        &mut self,
        _: &[usize],
        _: &mut EnvRng,
    ) -> Result<crate::envs::StepOutcome, crate::envs::EnvError> {
        self.at += 1;
        self.t += 1;
        Ok(crate::envs::StepOutcome {
            reward: 1.0,
            done: self.t == 3,
            truncated: false,
        })
    }
    fn obs(&self, _: usize) -> &[f32] {
        &[0.0]
    }
    fn executed(&self) -> &[usize] {
        &[0]
    }
    fn mac_done(&self) -> &[bool] {
        &[true]
    }
    fn t(&self) -> usize {
        self.t
    }
    fn render_ascii(&self) -> String {
        String::new()
    }
    fn draw(&self) -> Option<crate::draw::Picture> {
        let mut world = Canvas::new(40, 10, Colour::Background);
        world.fill_rect(10 * self.at as i64, 0, 10, 10, Colour::Goal);
        Some(crate::draw::Picture {
            world,
            agent_labels: &["W"],
        })
    }
}

#[test]
fn a_custom_domain_that_draws_renders_through_any_env() {
    let mut env = AnyEnv::hold("walk", Walk { at: 0, t: 0 });
    assert!(matches!(env, AnyEnv::Custom(_)));
    let mut rng = EnvRng::seed_from_u64(0);
    let frames = record_episode(&mut env, &mut rng, |_, _| {}).unwrap();
    assert_eq!(frames.len(), 4);
    for (k, frame) in frames.iter().enumerate() {
        // The lit cell moves one cell per step; the status bar is added below the 10-row world.
        assert_eq!(frame.image.width(), 40);
        assert!(frame.image.height() > 10);
        assert_eq!(
            frame.image.pixel(10 * k + 5, 5),
            Some(Colour::Goal),
            "frame {k}"
        );
    }
    assert_eq!(frames[3].team_return, 3.0);
}

#[test]
fn every_built_in_domain_draws_a_random_episode_into_a_gif() {
    // Each built-in domain at its default keys: a random episode records, encodes and decodes
    // frame for frame.
    for domain in crate::envs::registry::BUILT_IN {
        let spec = crate::envs::EnvSpec::of(*domain, &toml::Table::new()).unwrap();
        let mut env = spec.build().unwrap();
        let mut rng = EnvRng::seed_from_u64(3);
        let mut pick = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let n_actions = env.n_actions().to_vec();
        let frames = record_episode(&mut env, &mut rng, |_: &AnyEnv, actions: &mut [usize]| {
            for (a, &n) in actions.iter_mut().zip(&n_actions) {
                *a = pick.gen_range(0..n);
            }
        });
        let frames = frames.unwrap_or_else(|e| panic!("{}: {e}", domain.name()));
        assert!(frames.len() > 1, "{}", domain.name());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("episode.gif");
        write_gif(&frames, &path, 100).unwrap();
        assert_eq!(
            decode(&path).screens.len(),
            frames.len(),
            "{}",
            domain.name()
        );
    }
}
