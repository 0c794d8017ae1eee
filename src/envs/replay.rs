//! Replay of a macro-action log: a trajectory anyone can diff against the reference.
//!
//! A replay file is JSON: `{"env": "box-pushing", "grid": 10, "horizon": 100, "steps": [[a0, a1],
//! ...]}` (or `{"env": "warehouse", "horizon": 150, "steps": [[a0, a1, a2], ...]}`). The
//! environment is reset, then fed one joint action per primitive step until done or the steps run
//! out. An agent still busy with its macro-action ignores its entry, which may be -1 as in the
//! reference's logs; a free agent's entry must be a valid macro-action index.
//!
//! The reference form names the domain by its MacroMARL gym id and its keyword arguments:
//! `{"env": "BP-MA-v0", "params": {"grid_dim": [6, 6], ...}, "steps": [...]}`. The episode is then
//! as long as `steps` (the runner's horizon is not part of it; a domain whose env itself ends at a
//! horizon takes it from its params), `done` is the env's own terminal flag, and each line also
//! has `rewards` (the per-agent list the reference returns) and, for a domain with a global state,
//! `state` (the reference's `get_state()`), so the output diffs against the reference's trace
//! (`scripts/macromarl_traces.py`). `"source": "macromarl"` may name that origin. `params` records
//! the reference's `gym.make` call, so the kwargs MacroMARL's script passes to every environment
//! and this one does not read are left out, as the reference left them unread; any other key the
//! domain does not have is refused.
//!
//! ACAC's form adds `"source": "acac"`: `env` is ACAC's gym id (its macdec domain from
//! [`super::acac::GYM_IDS`]), `np_seed` (required) what `np.random.seed` got before the reset, and
//! for random starts (`params.rand_start`) `start_map`, the grid that reset produced; both become
//! the domain's replay keys, which check the grid against numpy's re-derived draws
//! (`docs/ACAC.md`, `scripts/acac_traces.py`).

use rand::SeedableRng;
use serde::Serialize;
use serde_json::Value;

use super::{EnvError, EnvRng, EnvSpec, MacroEnv};

/// Seed of the environment stream during a replay (Box Pushing never draws from it).
pub const REPLAY_SEED: u64 = 0;

/// A parsed replay file: which environment, and one row of actions per primitive step.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayFile {
    /// The domain and its config, reset before the first step.
    pub spec: EnvSpec,
    /// `steps[k][i]`: agent i's entry at primitive step k+1 (ignored while agent i is busy).
    pub steps: Vec<Vec<i64>>,
    /// The file named the domain by its reference id and `params` (see the module doc).
    pub reference_form: bool,
}

/// Why a replay file was refused. Messages name the step (1-based) and agent at fault.
#[derive(Debug, thiserror::Error)]
pub enum ReplayFileError {
    /// The text is not JSON.
    #[error("not valid JSON: {0}")]
    Json(#[source] serde_json::Error),
    /// The top level is not an object; holds what it is (e.g. `an array`).
    #[error("expected a JSON object with `env`, its parameters and `steps`, got {0}")]
    NotAnObject(&'static str),
    /// No `steps` field.
    #[error("missing field `steps` (a list with one list of actions per primitive step)")]
    MissingSteps,
    /// `steps` is not a list of lists of integers.
    #[error("`steps` must be a list of lists of integers: {0}")]
    BadSteps(#[source] serde_json::Error),
    /// The domain fields (`env` and its keys) do not describe a known domain.
    #[error("bad environment description: {0}")]
    BadSpec(#[source] serde_json::Error),
    /// A reference-form file's `params` do not fit the domain.
    #[error("bad environment description: {0}")]
    BadParams(#[source] super::spec::SpecError),
    /// `params` is not an object; holds what it is.
    #[error("`params` must be an object of the reference's keyword arguments, got {0}")]
    ParamsNotAnObject(&'static str),
    /// A `params` entry is null; holds its key.
    #[error("`params.{0}` holds a null, which is not a parameter value")]
    NullParam(String),
    /// A reference-form file without a string `env`.
    #[error("`env` must be a string naming the domain")]
    MissingEnv,
    /// The domain refused its config.
    #[error("cannot build the environment: {0}")]
    Build(#[source] EnvError),
    /// A row of `steps` with the wrong number of entries.
    #[error("step {step}: expected {expected} actions (one per agent), got {got}")]
    RowLength {
        /// Primitive step, 1-based.
        step: usize,
        /// Agents in the domain.
        expected: usize,
        /// Entries in the row.
        got: usize,
    },
    /// A free agent's entry is not one of its macro-actions.
    #[error("step {step}: agent {agent} is free and needs a macro-action in 0..{n_actions}, got {action}")]
    BadAction {
        /// Primitive step, 1-based.
        step: usize,
        /// The agent.
        agent: usize,
        /// The entry given.
        action: i64,
        /// Macro-actions the agent has.
        n_actions: usize,
    },
    /// The environment refused the step.
    #[error("step {step}: {source}")]
    Step {
        /// Primitive step, 1-based.
        step: usize,
        /// The environment's error.
        #[source]
        source: EnvError,
    },
    /// The replay could not be written out.
    #[error("writing the replay: {0}")]
    Output(#[from] std::io::Error),
}

/// Parse a replay file's text. Only the shape is checked here; actions are checked while
/// replaying, since an entry matters only when its agent is free.
pub fn parse_replay(text: &str) -> Result<ReplayFile, ReplayFileError> {
    let value: Value = serde_json::from_str(text).map_err(ReplayFileError::Json)?;
    let Value::Object(mut map) = value else {
        return Err(ReplayFileError::NotAnObject(json_kind(&value)));
    };
    let steps = map.remove("steps").ok_or(ReplayFileError::MissingSteps)?;
    let steps: Vec<Vec<i64>> = serde_json::from_value(steps).map_err(ReplayFileError::BadSteps)?;
    if let Some(params) = map.remove("params") {
        let spec = reference_spec(&map, params, steps.len())?;
        return Ok(ReplayFile {
            spec,
            steps,
            reference_form: true,
        });
    }
    let spec: EnvSpec =
        serde_json::from_value(Value::Object(map)).map_err(ReplayFileError::BadSpec)?;
    Ok(ReplayFile {
        spec,
        steps,
        reference_form: false,
    })
}

/// The domain of a reference-form file: `env` (the gym id or any name of the domain) with its
/// `params` as keys, and a horizon no shorter than `steps` unless the params set one.
fn reference_spec(
    map: &serde_json::Map<String, Value>,
    params: Value,
    n_steps: usize,
) -> Result<EnvSpec, ReplayFileError> {
    let Some(Value::String(env)) = map.get("env") else {
        return Err(ReplayFileError::MissingEnv);
    };
    let custom = |m: String| ReplayFileError::BadSpec(serde::de::Error::custom(m));
    let acac = match map.get("source") {
        None => false,
        Some(Value::String(s)) if s == "macromarl" => false,
        Some(Value::String(s)) if s == "acac" => true,
        Some(other) => {
            return Err(custom(format!(
                "`source` must be \"macromarl\" or \"acac\", got {other}"
            )))
        }
    };
    let fields: &[&str] = if acac {
        &["env", "source", "np_seed", "start_map"]
    } else {
        &["env", "source"]
    };
    if let Some(other) = map.keys().find(|k| !fields.contains(&k.as_str())) {
        return Err(custom(format!(
            "unknown field `{other}` beside `params` (this form has `{}`, `params` and `steps`)",
            fields.join("`, `")
        )));
    }
    let Value::Object(params) = params else {
        return Err(ReplayFileError::ParamsNotAnObject(json_kind(&params)));
    };
    let mut given = toml::Table::new();
    for (k, v) in &params {
        let value =
            super::domain::json_to_toml(v).ok_or_else(|| ReplayFileError::NullParam(k.clone()))?;
        given.insert(k.clone(), value);
    }
    let env = if acac {
        acac_start_keys(map, &mut given)?;
        super::acac::domain_of(env).ok_or_else(|| {
            custom(format!(
                "`{env}` is not an ACAC environment macdec has; ACAC's are {:?}",
                super::acac::GYM_IDS.map(|(id, _)| id)
            ))
        })?
    } else {
        env.as_str()
    };
    given
        .entry(super::domain::HORIZON_KEY)
        .or_insert_with(|| (n_steps.max(1) as i64).into());
    // `params` records the reference's gym.make call: the shared kwargs its env did not read
    // mean nothing here either (anything else unknown is refused by the domain).
    let domain = super::registry::lookup(env).map_err(|e| ReplayFileError::BadParams(e.into()))?;
    let own = domain
        .keys(&toml::Table::new())
        .expect("a domain's defaults are valid");
    let given = super::macromarl::kwargs_read(&given, &own);
    EnvSpec::of(domain, &given).map_err(ReplayFileError::BadParams)
}

/// The ACAC form's `np_seed` (required) and `start_map` (random starts only) as the domain's
/// replay keys when `params` ask for a random start; refused where they mean nothing.
fn acac_start_keys(
    map: &serde_json::Map<String, Value>,
    given: &mut toml::Table,
) -> Result<(), ReplayFileError> {
    let custom = |m: String| ReplayFileError::BadSpec(serde::de::Error::custom(m));
    let seed = match map.get("np_seed") {
        Some(Value::Number(n)) if n.as_u64().is_some_and(|s| s <= u64::from(u32::MAX)) => {
            n.as_u64().unwrap_or_default()
        }
        Some(v) => {
            return Err(custom(format!(
                "`np_seed` must be numpy's seed, an integer 0..=4294967295, got {v}"
            )))
        }
        None => {
            return Err(custom(
                "missing `np_seed` (what np.random.seed got before the reset)".into(),
            ))
        }
    };
    let random = given.get("rand_start") == Some(&toml::Value::Boolean(true));
    match (random, map.get("start_map")) {
        (false, Some(_)) => Err(custom(
            "`start_map` is for random starts only, and `params.rand_start` is not true".into(),
        )),
        (false, None) => Ok(()),
        (true, None) => Err(custom(
            "missing `start_map` (the grid the random start produced)".into(),
        )),
        (true, Some(grid)) => {
            let grid = super::domain::json_to_toml(grid)
                .ok_or_else(|| custom("`start_map` holds a null".into()))?;
            given.insert("np_seed".into(), (seed as i64).into());
            given.insert("start_map".into(), grid);
            Ok(())
        }
    }
}

fn json_kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// One output line. The first line (t = 0, after reset) has only `t` and `obs`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplayLine {
    /// Primitive steps since reset (0 on the first line).
    pub t: usize,
    /// The macro-action each agent ran during this step (absent on the first line).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub executed: Option<Vec<usize>>,
    /// Each agent's observation, in the spec's layout.
    pub obs: Vec<Vec<f32>>,
    /// The team reward of this step.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reward: Option<f64>,
    /// The per-agent reward list (reference form only): the team reward for every agent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rewards: Option<Vec<f64>>,
    /// Whether the episode ended here: the env's terminal flag in the reference form, else
    /// terminal or horizon.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub done: Option<bool>,
    /// Each agent's macro-action-done flag as 0 or 1.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mac_done: Option<Vec<u8>>,
    /// The global state (reference form, domains with one only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state: Option<Vec<f32>>,
}

/// A replayed line and, when asked for, the ASCII picture of the state after it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayFrame {
    /// The output line.
    pub line: ReplayLine,
    /// The ASCII picture of the state after the step, if asked for.
    pub picture: Option<String>,
}

/// The whole replay: one frame per line, and how many rows of `steps` were left unused because the
/// episode ended first.
#[derive(Debug, Clone, PartialEq)]
pub struct Replay {
    /// One frame per output line, the reset line first.
    pub frames: Vec<ReplayFrame>,
    /// Rows of `steps` left over because the episode ended first.
    pub unused_steps: usize,
}

fn all_obs<E: MacroEnv>(env: &E) -> Vec<Vec<f32>> {
    (0..env.n_agents()).map(|i| env.obs(i).to_vec()).collect()
}

/// Replay `file`: build and reset its environment, then feed its rows until done or the rows run
/// out. With `pictures`, each frame carries [`MacroEnv::render_ascii`] of the state after it. The
/// whole file is checked (row lengths up front, free agents' entries as they are reached) before
/// anything is returned, so a bad file yields an error and no partial output.
pub fn run_replay(file: &ReplayFile, pictures: bool) -> Result<Replay, ReplayFileError> {
    let mut frames = Vec::new();
    let unused_steps = walk(file, pictures, &mut |f| {
        frames.push(f);
        Ok(())
    })?;
    Ok(Replay {
        frames,
        unused_steps,
    })
}

/// [`run_replay`] without keeping the frames: each is handed to `on_frame` in order, so memory
/// stays one frame's worth however long the log. The file is first replayed once without output,
/// so a bad file still yields an error and no partial output. Returns the unused rows of `steps`.
pub fn stream_replay(
    file: &ReplayFile,
    pictures: bool,
    on_frame: &mut dyn FnMut(ReplayFrame) -> Result<(), ReplayFileError>,
) -> Result<usize, ReplayFileError> {
    walk(file, false, &mut |_| Ok(()))?;
    walk(file, pictures, on_frame)
}

/// The replay loop: every frame to `on_frame`; returns the unused rows of `steps`.
fn walk(
    file: &ReplayFile,
    pictures: bool,
    on_frame: &mut dyn FnMut(ReplayFrame) -> Result<(), ReplayFileError>,
) -> Result<usize, ReplayFileError> {
    let mut env = file.spec.build().map_err(ReplayFileError::Build)?;
    let n_agents = env.n_agents();
    if let Some((k, row)) = file
        .steps
        .iter()
        .enumerate()
        .find(|(_, row)| row.len() != n_agents)
    {
        return Err(ReplayFileError::RowLength {
            step: k + 1,
            expected: n_agents,
            got: row.len(),
        });
    }
    let mut rng = EnvRng::seed_from_u64(REPLAY_SEED);
    env.reset(&mut rng);
    let picture = |env: &super::AnyEnv| pictures.then(|| env.render_ascii());
    let state = |env: &super::AnyEnv| {
        (file.reference_form && env.state_size() > 0).then(|| {
            let mut s = vec![0.0; env.state_size()];
            env.write_state(&mut s);
            s
        })
    };
    on_frame(ReplayFrame {
        line: ReplayLine {
            t: 0,
            executed: None,
            obs: all_obs(&env),
            reward: None,
            rewards: None,
            done: None,
            mac_done: None,
            state: state(&env),
        },
        picture: picture(&env),
    })?;
    let mut actions = vec![0usize; n_agents];
    let mut used = 0;
    for (k, row) in file.steps.iter().enumerate() {
        let step = k + 1;
        for (agent, (&entry, slot)) in row.iter().zip(actions.iter_mut()).enumerate() {
            if !env.is_free(agent) {
                *slot = 0; // ignored by the environment
                continue;
            }
            let n_actions = env.n_actions()[agent];
            *slot = usize::try_from(entry)
                .ok()
                .filter(|&a| a < n_actions)
                .ok_or(ReplayFileError::BadAction {
                    step,
                    agent,
                    action: entry,
                    n_actions,
                })?;
        }
        let out = env
            .step(&actions, &mut rng)
            .map_err(|source| ReplayFileError::Step { step, source })?;
        used += 1;
        on_frame(ReplayFrame {
            line: ReplayLine {
                t: env.t(),
                executed: Some(env.executed().to_vec()),
                obs: all_obs(&env),
                reward: Some(out.reward),
                rewards: file.reference_form.then(|| vec![out.reward; n_agents]),
                done: Some(if file.reference_form {
                    out.terminal()
                } else {
                    out.done
                }),
                mac_done: Some(env.mac_done().iter().map(|&d| u8::from(d)).collect()),
                state: state(&env),
            },
            picture: picture(&env),
        })?;
        if out.done {
            break;
        }
    }
    Ok(file.steps.len() - used)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bp10(steps: &str) -> String {
        format!(r#"{{"env": "box-pushing", "grid": 10, "horizon": 100, "steps": {steps}}}"#)
    }

    /// Scenario S2 as a log: robot 0 BB0, robot 1 BB1, then -1 while busy, then Push.
    fn s2_log() -> String {
        let mut rows = vec!["[2, 3]".to_string()];
        rows.extend((0..6).map(|_| "[-1, -1]".to_string()));
        rows.push("[4, 4]".to_string());
        rows.extend((0..5).map(|_| "[-1, -1]".to_string()));
        bp10(&format!("[{}]", rows.join(", ")))
    }

    #[test]
    fn s2_log_replays_to_the_spec_trace_and_prints_spec_json() {
        let file = parse_replay(&s2_log()).unwrap();
        let replay = run_replay(&file, false).unwrap();
        assert_eq!(replay.frames.len(), 12);
        assert_eq!(replay.unused_steps, 2);
        let first = serde_json::to_string(&replay.frames[0].line).unwrap();
        assert_eq!(
            first,
            r#"{"t":0,"obs":[[0.0,0.0,1.0,0.0,0.0],[0.0,0.0,1.0,0.0,0.0]]}"#
        );
        let seventh = serde_json::to_string(&replay.frames[7].line).unwrap();
        assert_eq!(
            seventh,
            r#"{"t":7,"executed":[2,3],"obs":[[0.0,1.0,0.0,0.0,0.0],[0.0,1.0,0.0,0.0,0.0]],"reward":-0.1,"done":false,"mac_done":[1,1]}"#
        );
        let last = &replay.frames[11].line;
        assert_eq!(last.reward, Some(99.9));
        assert_eq!(last.done, Some(true));
        assert_eq!(last.executed, Some(vec![4, 4]));
    }

    #[test]
    fn pictures_come_with_every_frame_when_asked() {
        let file = parse_replay(&bp10("[[7, 7]]")).unwrap();
        let replay = run_replay(&file, true).unwrap();
        assert_eq!(replay.frames.len(), 2);
        assert!(replay.frames[1]
            .picture
            .as_ref()
            .unwrap()
            .starts_with("t=1 "));
    }

    fn error_of(text: &str) -> String {
        match parse_replay(text).and_then(|f| run_replay(&f, false)) {
            Ok(_) => panic!("accepted a bad file: {text}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn bad_files_are_refused_with_the_reason() {
        assert!(error_of("{").contains("not valid JSON"));
        assert!(error_of("[1, 2]").contains("got an array"));
        let e = error_of(r#"{"env": "box-pushing", "grid": 10, "horizon": 100}"#);
        assert!(e.contains("missing field `steps`"), "{e}");
        let e = error_of(r#"{"env": "sokoban", "horizon": 100, "steps": []}"#);
        assert!(e.contains("unknown domain `sokoban`"), "{e}");
        let e = error_of(r#"{"env": "box-pushing", "horizon": 100, "steps": []}"#);
        assert!(e.contains("missing field `grid`"), "{e}");
        let e = error_of(r#"{"env": "box-pushing", "grid": 7, "horizon": 100, "steps": []}"#);
        assert!(e.contains("grid_dim") && e.contains("got 7"), "{e}");
        let e = error_of(r#"{"env": "warehouse", "horizon": 0, "steps": []}"#);
        assert!(e.contains("env_terminate_step"), "{e}");
        let e = error_of(&bp10("[[1, 2], [3]]"));
        assert_eq!(e, "step 2: expected 2 actions (one per agent), got 1");
        let e = error_of(&bp10("[[1, 8]]"));
        assert_eq!(
            e,
            "step 1: agent 1 is free and needs a macro-action in 0..8, got 8"
        );
        let e = error_of(&bp10("[[-1, 7]]"));
        assert!(e.starts_with("step 1: agent 0 is free"), "{e}");
        let e = error_of(&bp10("[[1.5, 7]]"));
        assert!(e.contains("`steps` must be"), "{e}");
    }

    #[test]
    fn the_reference_form_prints_what_the_reference_returns() {
        let text = r#"{"env": "BP-MA-v0", "params": {"grid_dim": [6, 6], "TB_move_speed": 0.6},
            "steps": [[2, 3], [-1, -1], [-1, -1], [-1, -1], [4, 4], [-1, -1], [7, 7]]}"#;
        let file = parse_replay(text).unwrap();
        assert!(file.reference_form);
        // The runner's horizon is the file's length, so only the env's own terminal ends it.
        assert_eq!(file.spec.horizon(), 7);
        let replay = run_replay(&file, false).unwrap();
        assert_eq!((replay.frames.len(), replay.unused_steps), (7, 1));
        let first = &replay.frames[0].line;
        assert_eq!(first.state.as_ref().map(Vec::len), Some(18));
        let last = &replay.frames[6].line;
        assert_eq!(last.rewards, Some(vec![299.9, 299.9]));
        assert_eq!(last.done, Some(true));
        // A horizon cut is not the env's terminal: done stays false on the last line.
        let cut = r#"{"env": "BP-MA-v0", "params": {}, "steps": [[7, 7], [7, 7]]}"#;
        let replay = run_replay(&parse_replay(cut).unwrap(), false).unwrap();
        assert_eq!(replay.frames[2].line.done, Some(false));
        // The ICRA form keeps its lines: no rewards, no state.
        let icra = run_replay(&parse_replay(&bp10("[[7, 7]]")).unwrap(), false).unwrap();
        assert!(icra.frames[1].line.rewards.is_none() && icra.frames[1].line.state.is_none());
    }

    #[test]
    fn bad_reference_forms_name_the_problem() {
        let e = error_of(r#"{"env": "BP-MA-v0", "params": [1], "steps": []}"#);
        assert!(e.contains("`params` must be an object"), "{e}");
        let e = error_of(r#"{"env": "BP-MA-v0", "params": {"penalty": null}, "steps": []}"#);
        assert!(e.contains("`params.penalty` holds a null"), "{e}");
        let e = error_of(r#"{"env": "BP-MA-v0", "grid": 6, "params": {}, "steps": []}"#);
        assert!(e.contains("unknown field `grid`"), "{e}");
        let e = error_of(r#"{"params": {}, "steps": []}"#);
        assert!(e.contains("`env` must be a string"), "{e}");
        let e = error_of(r#"{"env": "BP-MA-v0", "params": {"colour": 1}, "steps": []}"#);
        assert!(e.contains("`colour`: not a key of this domain"), "{e}");
    }

    #[test]
    fn bad_acac_forms_name_the_problem() {
        let ovc = |extra: &str, params: &str| {
            format!(
                r#"{{"source": "acac", "env": "Overcooked-MA-v1", "params": {{{params}}}{extra}, "steps": [[0, 0, 0]]}}"#
            )
        };
        let e = error_of(&ovc("", ""));
        assert!(e.contains("missing `np_seed`"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": -3"#, ""));
        assert!(e.contains("`np_seed` must be numpy's seed"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": 1, "start_map": [[1]]"#, ""));
        assert!(e.contains("`start_map` is for random starts only"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": 1"#, r#""rand_start": true"#));
        assert!(e.contains("missing `start_map`"), "{e}");
        let e = error_of(&ovc(
            r#", "np_seed": 1, "start_map": [[1, 1], [1, 1]]"#,
            r#""rand_start": true"#,
        ));
        assert!(e.contains("`start_map`: must be 7 rows of 7 cells"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": 1"#, r#""n_agent": 6"#));
        assert!(e.contains("`n_agent`"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": 1, "seed": 2"#, ""));
        assert!(e.contains("unknown field `seed`"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": 1"#, "").replace("acac", "pymarl"));
        assert!(e.contains("`source` must be"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": 1"#, "").replace("MA-v1", "MA-v7"));
        assert!(e.contains("not an ACAC environment"), "{e}");
        // ACAC's fixed start is fine with np_seed alone; macdec's own form keeps refusing it.
        assert!(parse_replay(&ovc(r#", "np_seed": 1"#, "")).is_ok());
        let e = error_of(r#"{"env": "BP-MA-v0", "np_seed": 1, "params": {}, "steps": []}"#);
        assert!(e.contains("unknown field `np_seed`"), "{e}");
    }

    #[test]
    fn bad_overcooked_large_forms_name_the_problem() {
        let ovc = |extra: &str, params: &str| {
            format!(
                r#"{{"source": "acac", "env": "Overcooked-MA-v0", "params": {{{params}}}{extra}, "steps": [[0, 0, 0, 0, 0, 0]]}}"#
            )
        };
        assert!(parse_replay(&ovc(r#", "np_seed": 1"#, "")).is_ok());
        let e = error_of(&ovc(r#", "np_seed": 1"#, r#""n_agent": 7"#));
        assert!(e.contains("`n_agent`") && e.contains("2..=6"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": 1"#, r#""obj": ["lettuce"]"#));
        assert!(e.contains("`obj`") && e.contains("one character"), "{e}");
        let e = error_of(&ovc(r#", "np_seed": 1"#, r#""grid_dim": [7, 7]"#));
        assert!(e.contains("`grid_dim`") && e.contains("[11, 11]"), "{e}");
        let e = error_of(&ovc(
            r#", "np_seed": 1, "start_map": [[1, 1], [1, 1]]"#,
            r#""rand_start": true"#,
        ));
        assert!(e.contains("must be 11 rows of 11 cells"), "{e}");
        let mut rows = vec![vec![1; 11]; 11];
        rows[0][3] = 12;
        let e = error_of(&ovc(
            &format!(r#", "np_seed": 1, "start_map": {rows:?}"#),
            r#""rand_start": true"#,
        ));
        assert!(e.contains("cell (0, 3) holds 12, not a code"), "{e}");
    }

    #[test]
    fn busy_agents_may_hold_any_integer() {
        let file = parse_replay(&bp10("[[2, 7], [-1, 7], [99, 7]]")).unwrap();
        let replay = run_replay(&file, false).unwrap();
        assert_eq!(replay.frames.len(), 4);
        assert_eq!(replay.frames[3].line.executed, Some(vec![2, 7]));
    }

    #[test]
    fn streaming_gives_the_frames_of_run_replay_and_nothing_for_a_bad_file() {
        let text = r#"{"env": "box-pushing", "grid": 10, "horizon": 30, "steps": [[0, 1], [2, 3], [4, 4], [1, 1]]}"#;
        let file = parse_replay(text).unwrap();
        let whole = run_replay(&file, true).unwrap();
        let mut streamed = Vec::new();
        let unused = stream_replay(&file, true, &mut |f| {
            streamed.push(f);
            Ok(())
        })
        .unwrap();
        assert_eq!(streamed, whole.frames);
        assert_eq!(unused, whole.unused_steps);
        // A bad action (checked only once the t = 0 frame exists): no frame is emitted at all.
        let bad =
            r#"{"env": "box-pushing", "grid": 10, "horizon": 30, "steps": [[99, 99], [0, 0]]}"#;
        let file = parse_replay(bad).unwrap();
        let mut n = 0;
        assert!(stream_replay(&file, false, &mut |_| {
            n += 1;
            Ok(())
        })
        .is_err());
        assert_eq!(n, 0);
    }
}
