//! Experiment configs: the TOML files in `experiments/`, `--set` overrides, sweep grids, and the
//! fully resolved, validated configuration of one run.
//!
//! Keys are the reference's command-line flag names (`total_epi`, `trace_len`, `l_rate`, ...), so a
//! reference command translates key for key. Every key has the paper's value as its default for the
//! chosen domain and method (`docs/ALGORITHMS.md` §10): `env_name = "BP_MA"` alone is Figure 4a's
//! setting. A key given as a list is a sweep axis; the grid's points become named variants.

use crate::algos::families::{Family, Method, RunConfig};
use crate::envs::domain::NOT_A_KEY;
use crate::envs::{EnvShape, EnvSpec};
use crate::experiment::definition::limits;
use crate::experiment::definition::names::{check_curve_name, check_experiment_name, NameError};
use crate::experiment::definition::run_settings::RunSettings;
use crate::experiment::definition::seeds::{check_seed_list, parse_seeds, SeedsError};
use crate::experiment::run::results_tree;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Why a config could not be used. Messages name the file, the key and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The experiment file could not be read.
    #[error("{path}: cannot read: {source}")]
    Read {
        /// The experiment file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not valid TOML.
    #[error("{path}: not valid TOML: {message}")]
    Toml {
        /// The experiment file.
        path: PathBuf,
        /// The TOML parser's reason.
        message: String,
    },
    /// A key the method's family and the domain do not have (a typo, a flag the reference does
    /// not have, or another family's key).
    #[error("{path}: unknown key `{key}` for {method} ({hint})")]
    UnknownKey {
        /// The experiment file.
        path: PathBuf,
        /// The key, as written.
        key: String,
        /// The method whose config was being resolved.
        method: Method,
        /// The nearest keys of the method's own family and domain, or which family has the key.
        hint: String,
    },
    /// A known key with a value of the wrong type or out of range.
    #[error("{path}: `{key}`: {message}")]
    BadValue {
        /// The experiment file.
        path: PathBuf,
        /// The key, as written.
        key: String,
        /// What was expected.
        message: String,
    },
    /// The `seeds` field cannot be parsed.
    #[error("{path}: {source}")]
    Seeds {
        /// The experiment file.
        path: PathBuf,
        /// Why.
        source: SeedsError,
    },
    /// A `--set` item without `=`; holds the item as given.
    #[error("--set `{0}`: expected key=value, e.g. total_epi=300 or dec-hddrqn.init_h=0.3")]
    BadSet(String),
    /// A `--set` item whose value does not parse or validate.
    #[error("--set `{item}`: {message}")]
    BadSetValue {
        /// The item as given.
        item: String,
        /// What was expected.
        message: String,
    },
    /// The file (after `--methods`) selects no method.
    #[error("{path}: no methods to run")]
    NoMethods {
        /// The experiment file.
        path: PathBuf,
    },
    /// The experiment name cannot name a results directory.
    #[error("{path}: {source} (set `name = \"...\"` in the file)")]
    BadName {
        /// The experiment file.
        path: PathBuf,
        /// Why the name is refused.
        source: NameError,
    },
    /// An entry (e.g. a method) listed twice.
    #[error("{path}: {what} `{value}` is listed twice; each run must appear once")]
    Duplicate {
        /// The experiment file.
        path: PathBuf,
        /// What is repeated, e.g. `method`.
        what: &'static str,
        /// The repeated entry.
        value: String,
    },
    /// Two sweep points of one method that resolve to the same config.
    #[error("{path}: {method} sweep points `{a}` and `{b}` resolve to the same config; list each value once")]
    DuplicatePoint {
        /// The experiment file.
        path: PathBuf,
        /// The method's name.
        method: &'static str,
        /// The first point's variant name.
        a: String,
        /// The second point's variant name.
        b: String,
    },
    /// Methods x sweep points x seeds exceeds the runner's limit.
    #[error("{path}: the experiment expands to {count} runs, at most {max} allowed (fewer seeds or sweep values)")]
    TooManyRuns {
        /// The experiment file.
        path: PathBuf,
        /// The number of runs, as text (`at least N` when counting stopped early).
        count: String,
        /// The limit.
        max: usize,
    },
}

/// The experiment file as written: name, methods, seeds, shared params, per-method overrides.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct ExperimentFile {
    name: Option<String>,
    methods: Option<Vec<String>>,
    seeds: Option<SeedsField>,
    #[serde(default)]
    params: toml::Table,
    #[serde(default)]
    method: BTreeMap<String, toml::Table>,
    #[serde(default)]
    shared_curves: BTreeMap<String, String>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum SeedsField {
    Text(String),
    List(Vec<u64>),
}

/// One training run to perform: a method, a sweep point and a seed, with its resolved config.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// The experiment's name (first component of the run directory).
    pub experiment: String,
    /// The method trained.
    pub method: Method,
    /// Empty when the experiment has no sweep; else e.g. `trace_len=10,l_rate=0.001`.
    pub variant: String,
    /// The run's seed; every random stream of the run derives from it.
    pub seed: u64,
    /// The domain the run trains on.
    pub env: EnvSpec,
    /// The run's hyperparameters.
    pub config: RunConfig,
}

impl RunSpec {
    /// The run's directory below the results root: `<experiment>/<method>[@<variant>]/seed-<k>`.
    pub fn dir(&self, results_root: &Path) -> PathBuf {
        results_tree::run_dir(
            results_root,
            &self.experiment,
            &self.curve_name(),
            self.seed,
        )
    }

    /// The name of the curve this run belongs to: the method, plus the sweep point if any.
    pub fn curve_name(&self) -> String {
        if self.variant.is_empty() {
            self.method.name().to_string()
        } else {
            format!("{}@{}", self.method.name(), self.variant)
        }
    }
}

/// A parsed experiment: everything needed to list its runs.
#[derive(Debug, Clone)]
pub struct Experiment {
    /// The experiment's name, also its results directory.
    pub name: String,
    /// The methods to run, in file order (after `--methods`).
    pub methods: Vec<Method>,
    /// The seeds each method and sweep point runs with.
    pub seeds: Vec<u64>,
    /// Curves whose runs belong to another experiment (curve name -> that experiment's name):
    /// Figure 6's Our-2 is Figure 5's Our-2, trained once and drawn in both. All the file
    /// names, also when `--methods` selects fewer (the plots need them all).
    pub shared_curves: BTreeMap<String, String>,
    path: PathBuf,
    params: toml::Table,
    per_method: BTreeMap<Method, toml::Table>,
}

/// The file in `<results>/<experiment>/` naming the curves that live in another experiment's
/// directory (`our2 = "fig5_wtd"`), written by `macdec train` and read by `macdec plot`.
pub use crate::experiment::run::results_tree::SHARED_CURVES as SHARED_CURVES_FILE;

/// The command-line overrides of `macdec train`.
#[derive(Debug, Clone, Default)]
pub struct Overrides {
    /// Run only these methods (`--methods`), instead of the file's.
    pub methods: Option<Vec<Method>>,
    /// Run these seeds (`--seeds`), instead of the file's.
    pub seeds: Option<Vec<u64>>,
    /// `key=value` pairs; `method.key=value` targets one method.
    pub set: Vec<String>,
}

/// The embedded default experiment, the README's first command: the first family's quick
/// start (a short Box Pushing 10x10 Our-1 run, a few minutes on two cores).
pub fn default_experiment() -> (&'static str, &'static str) {
    let facts = Family::ALL[0].facts();
    (facts.quick_start, facts.quick_start_name)
}

/// The method an experiment file without `methods` trains (the ICRA paper's Our-1).
pub const DEFAULT_METHOD: &str = "our1";

/// The built-in experiment (text, name) `train` runs without `--config` for these `--methods`:
/// their family's quick start ([`crate::algos::family::FamilyFacts::quick_start`]; the default
/// experiment without `--methods`). Methods of several families have no common quick start: the
/// error lists each family's methods and says where the experiment files are.
pub fn quick_start(methods: Option<&[Method]>) -> Result<(&'static str, &'static str), String> {
    let families: std::collections::BTreeSet<Family> =
        methods.unwrap_or(&[]).iter().map(|m| m.family()).collect();
    let mut families = families.into_iter();
    match (families.next(), families.next()) {
        (None, _) => Ok(default_experiment()),
        (Some(f), None) => Ok((f.facts().quick_start, f.facts().quick_start_name)),
        (Some(_), Some(_)) => {
            let lists: Vec<String> = Family::ALL
                .iter()
                .map(|f| {
                    let names: Vec<&str> = f.methods().iter().map(|m| m.name()).collect();
                    format!(
                        "{} ({}: {})",
                        f.facts().description,
                        f.facts().quick_start_name,
                        names.join(", ")
                    )
                })
                .collect();
            Err(format!(
                "without --config, train runs one family's quick start; name methods of one \
                 family: {}; or pass --config (e.g. experiments/macromarl/bp6.toml, whose domain \
                 both families train on)",
                lists.join("; ")
            ))
        }
    }
}

impl Experiment {
    /// Load an experiment file and apply command-line overrides.
    pub fn load(path: &Path, overrides: &Overrides) -> Result<Self, ConfigError> {
        let text = crate::files::bounded_read::read_text_file(
            path,
            crate::files::bounded_read::MAX_TEXT_BYTES,
        )
        .map_err(|source| ConfigError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "experiment".into());
        Self::parse(&text, path, &stem, overrides)
    }

    /// Parse experiment TOML text; `path` is only used in messages, `default_name` when the file
    /// has no `name`.
    pub fn parse(
        text: &str,
        path: &Path,
        default_name: &str,
        overrides: &Overrides,
    ) -> Result<Self, ConfigError> {
        let p = || path.to_path_buf();
        let file: ExperimentFile = toml::from_str(text).map_err(|e| ConfigError::Toml {
            path: p(),
            message: e.message().to_string(),
        })?;
        // The file's own methods (checked even when --methods selects some of them).
        let listed: Option<Vec<Method>> = file
            .methods
            .as_ref()
            .map(|names| {
                names
                    .iter()
                    .map(|n| {
                        n.parse::<Method>().map_err(|e| ConfigError::BadValue {
                            path: p(),
                            key: "methods".into(),
                            message: e.to_string(),
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()
            })
            .transpose()?;
        let methods = match (&overrides.methods, &listed) {
            (Some(m), _) => m.clone(),
            (None, Some(l)) => l.clone(),
            (None, None) => vec![DEFAULT_METHOD.parse().expect("the default method exists")],
        };
        if methods.is_empty() {
            return Err(ConfigError::NoMethods { path: p() });
        }
        for (i, m) in methods.iter().enumerate() {
            if methods[..i].contains(m) {
                return Err(ConfigError::Duplicate {
                    path: p(),
                    what: "method",
                    value: m.name().to_string(),
                });
            }
        }
        let name = file.name.unwrap_or_else(|| default_name.to_string());
        check_experiment_name(&name)
            .map_err(|source| ConfigError::BadName { path: p(), source })?;
        let seeds = match (&overrides.seeds, file.seeds) {
            (Some(s), _) => {
                // Checked here too: a library or Python caller fills `Overrides` directly.
                check_seed_list(s).map_err(|source| ConfigError::Seeds { path: p(), source })?;
                s.clone()
            }
            (None, Some(SeedsField::Text(t))) => {
                parse_seeds(&t).map_err(|source| ConfigError::Seeds { path: p(), source })?
            }
            (None, Some(SeedsField::List(l))) => {
                check_seed_list(&l).map_err(|source| ConfigError::Seeds { path: p(), source })?;
                l
            }
            (None, None) => vec![0],
        };
        let mut params = file.params;
        let mut per_method = BTreeMap::new();
        for (name, table) in file.method {
            let m = name.parse::<Method>().map_err(|e| ConfigError::BadValue {
                path: p(),
                key: format!("method.{name}"),
                message: e.to_string(),
            })?;
            per_method.insert(m, table);
        }
        for item in &overrides.set {
            let (key, value) = parse_set(item)?;
            match key.split_once('.') {
                Some((m, k)) => {
                    let m = m.parse::<Method>().map_err(|e| ConfigError::BadSetValue {
                        item: item.clone(),
                        message: e.to_string(),
                    })?;
                    per_method
                        .entry(m)
                        .or_default()
                        .insert(k.to_string(), value);
                }
                None => {
                    // A command-line value wins over the file's per-method values too.
                    for table in per_method.values_mut() {
                        table.remove(&key);
                    }
                    params.insert(key, value);
                }
            }
        }
        for (curve, home) in &file.shared_curves {
            let bad = |message: String| ConfigError::BadValue {
                path: p(),
                key: format!("shared_curves.{curve}"),
                message,
            };
            let own = listed.as_ref().unwrap_or(&methods);
            if !own.iter().any(|m| m.name() == curve) {
                return Err(bad(format!(
                    "`{curve}` is not one of this experiment's methods"
                )));
            }
            if let Err(e) = check_experiment_name(home) {
                return Err(bad(format!("expected an experiment name: {e}")));
            }
        }
        let exp = Experiment {
            name,
            methods,
            seeds,
            shared_curves: file.shared_curves,
            path: p(),
            params,
            per_method,
        };
        // Resolve every run once now, so a typo fails before any run starts; sections of methods
        // not selected are checked too, so a typo there is not silently kept for a later run.
        exp.runs()?;
        for &method in exp.per_method.keys() {
            if !exp.methods.contains(&method) {
                exp.method_points(method)?;
            }
        }
        Ok(exp)
    }

    /// One method's sweep points: (variant name, resolved config), checked and deduplicated.
    fn method_points(&self, method: Method) -> Result<Vec<(String, RunSettings)>, ConfigError> {
        let mut table = self.params.clone();
        if let Some(extra) = self.per_method.get(&method) {
            for (k, v) in extra {
                table.insert(k.clone(), v.clone());
            }
        }
        let mut points: Vec<(String, RunSettings)> = Vec::new();
        // Keyed by the resolved config's TOML text: `1e-3` and `0.001`, or `1` and `1.0`, are
        // one point and would race in one directory's worth of work twice.
        let mut seen: std::collections::HashMap<String, String> = Default::default();
        for (variant, point) in expand_grid(&self.path, &table)? {
            let config = resolve(&self.path, method, &point)?;
            let key = toml::to_string(&config).expect("RunSettings serializes to TOML");
            if let Some(other) = seen.insert(key, variant.clone()) {
                return Err(ConfigError::DuplicatePoint {
                    path: self.path.clone(),
                    method: method.name(),
                    a: other,
                    b: variant,
                });
            }
            points.push((variant, config));
        }
        Ok(points)
    }

    /// Every (method, sweep point, seed) run, methods outermost, seeds innermost.
    pub fn runs(&self) -> Result<Vec<RunSpec>, ConfigError> {
        let mut runs = Vec::new();
        for &method in &self.methods {
            let points = self.method_points(method)?;
            let count = runs.len() as u128 + points.len() as u128 * self.seeds.len() as u128;
            if count > limits::MAX_RUNS as u128 {
                return Err(ConfigError::TooManyRuns {
                    path: self.path.clone(),
                    count: format!("at least {count}"),
                    max: limits::MAX_RUNS,
                });
            }
            // A shared curve's runs live (and are identified) under the experiment they belong
            // to; their resolved config must match that experiment's, or the run directory
            // refuses them.
            let experiment = self
                .shared_curves
                .get(method.name())
                .unwrap_or(&self.name)
                .clone();
            for (variant, config) in points {
                let curve = if variant.is_empty() {
                    method.name().to_string()
                } else {
                    format!("{}@{variant}", method.name())
                };
                check_curve_name(&curve).map_err(|source| ConfigError::BadName {
                    path: self.path.clone(),
                    source,
                })?;
                for &seed in &self.seeds {
                    runs.push(RunSpec {
                        experiment: experiment.clone(),
                        method,
                        variant: variant.clone(),
                        seed,
                        env: config.env.clone(),
                        config: config.config.clone(),
                    });
                }
            }
        }
        Ok(runs)
    }
}

impl Experiment {
    /// Record the experiment's shared curves in `<out>/<name>/shared_curves.toml` so plots find
    /// them; nothing is written for an experiment without any.
    pub fn write_shared_curves(&self, out: &Path) -> std::io::Result<()> {
        if self.shared_curves.is_empty() {
            return Ok(());
        }
        let text = toml::to_string(&self.shared_curves).map_err(std::io::Error::other)?;
        let dir = out.join(&self.name);
        crate::files::links::create_real_dirs(out, &dir)?;
        crate::files::atomic::write_atomic(&dir.join(SHARED_CURVES_FILE), text.as_bytes())
    }
}

fn parse_set(item: &str) -> Result<(String, toml::Value), ConfigError> {
    let (key, raw) = item
        .split_once('=')
        .ok_or_else(|| ConfigError::BadSet(item.to_string()))?;
    let key = key.trim();
    if key.is_empty() {
        return Err(ConfigError::BadSet(item.to_string()));
    }
    // Read the value as TOML (numbers, booleans, lists); a bare word is a string.
    let parsed = toml::from_str::<toml::Table>(&format!("v = {raw}")).ok();
    // A newline in the value would start another key (`total_epi=3\ngamma=0.5` parses as two);
    // one --set is one key, so that is refused rather than half applied.
    if parsed.as_ref().is_some_and(|t| t.len() > 1)
        || (parsed.is_none() && raw.contains(['\n', '\r']))
    {
        return Err(ConfigError::BadSetValue {
            item: item.to_string(),
            message: "the value holds a line break; give one key per --set".into(),
        });
    }
    let parsed = parsed.and_then(|mut t| t.remove("v"));
    let word = raw.trim();
    let value = match parsed {
        Some(v) => v,
        // A number TOML cannot hold is not a string the user meant.
        None if looks_numeric(word) => {
            return Err(ConfigError::BadSetValue {
                item: item.to_string(),
                message: format!(
                    "`{word}` is not a number this config can hold (integers are at most {})",
                    i64::MAX
                ),
            })
        }
        None => toml::Value::String(word.to_string()),
    };
    Ok((key.to_string(), value))
}

/// Whether `word` is written like a number (digits with an optional sign, point or exponent).
fn looks_numeric(word: &str) -> bool {
    let w = word.trim_start_matches(['+', '-']);
    w.starts_with(|c: char| c.is_ascii_digit())
        && w.chars()
            .all(|c| c.is_ascii_digit() || "._eE+-".contains(c))
}

/// How deeply lists nest in `v`: 0 for a plain value, 1 for a list of plain values, ...
fn list_depth(v: &toml::Value) -> usize {
    match v {
        toml::Value::Array(items) => 1 + items.first().map_or(0, list_depth),
        _ => 0,
    }
}

/// For each key whose value is itself a list (the actor-critic MLP widths, and the list keys
/// of the domain `table` names: `env_name`, Box Pushing when absent, every name of a swept
/// `env_name`), the depth of that list: such a key's value is one value at that depth and a
/// sweep one level deeper (`human_speed_per_step = [[18, 18, 18, 18], [18, 18, 18, 18]]` is
/// one setting, `a_mlp_layer_size = [[32, 32], [64, 64]]` two).
fn list_valued_keys(table: &toml::Table) -> std::collections::HashMap<String, usize> {
    let names: Vec<&str> = match table.get("env_name") {
        Some(toml::Value::String(name)) => vec![name.as_str()],
        Some(toml::Value::Array(items)) => items.iter().filter_map(|v| v.as_str()).collect(),
        _ => vec!["BP_MA"],
    };
    // A family's list keys (the actor-critic MLP widths) are lists by nature for every domain.
    let mut depths: std::collections::HashMap<String, usize> = Family::ALL
        .iter()
        .flat_map(|f| f.facts().list_keys)
        .map(|k| (k.to_string(), 1))
        .collect();
    for name in names {
        let Ok(domain) = crate::envs::registry::lookup(name) else {
            continue; // resolve names the bad env_name
        };
        for (key, default) in domain.keys(&toml::Table::new()).unwrap_or_default() {
            let depth = list_depth(&default);
            if depth > 0 {
                let d = depths.entry(key).or_insert(0);
                *d = depth.max(*d);
            }
        }
    }
    depths
}

/// Expand list-valued keys into the grid of their combinations (keys sorted by
/// name, so variant names are stable). Each point is named by its swept keys. An empty list and
/// a grid beyond [`limits::MAX_RUNS`] points are refused before anything is expanded. A key
/// whose value is a list by nature ([`list_valued_keys`]) is swept only by a list of such lists.
fn expand_grid(
    path: &Path,
    table: &toml::Table,
) -> Result<Vec<(String, toml::Table)>, ConfigError> {
    let list_valued = list_valued_keys(table);
    let is_sweep = |key: &String, value: &toml::Value| {
        matches!(value, toml::Value::Array(_))
            && list_depth(value) > list_valued.get(key).copied().unwrap_or(0)
    };
    let mut size: u128 = 1;
    for (key, value) in table {
        if !is_sweep(key, value) {
            continue;
        }
        if let toml::Value::Array(items) = value {
            if items.is_empty() {
                return Err(ConfigError::BadValue {
                    path: path.to_path_buf(),
                    key: key.clone(),
                    message: "an empty list sweeps nothing; give at least one value".into(),
                });
            }
            size = size.saturating_mul(items.len() as u128);
        }
    }
    if size > limits::MAX_RUNS as u128 {
        return Err(ConfigError::TooManyRuns {
            path: path.to_path_buf(),
            count: format!("{size} sweep points, so at least {size}"),
            max: limits::MAX_RUNS,
        });
    }
    let mut points = vec![(String::new(), toml::Table::new())];
    // Keys in name order, so a variant's name does not depend on how the file orders them.
    let mut keys: Vec<(&String, &toml::Value)> = table.iter().collect();
    keys.sort_by_key(|(k, _)| *k);
    for (key, value) in keys {
        let swept = is_sweep(key, value);
        let choices: Vec<toml::Value> = match value {
            toml::Value::Array(items) if swept => items.clone(),
            other => vec![other.clone()],
        };
        let mut next = Vec::with_capacity(points.len() * choices.len());
        for (name, point) in &points {
            for choice in &choices {
                let mut point = point.clone();
                point.insert(key.clone(), choice.clone());
                let name = if swept {
                    let label = format!("{key}={}", value_label(choice));
                    if name.is_empty() {
                        label
                    } else {
                        format!("{name},{label}")
                    }
                } else {
                    name.clone()
                };
                next.push((name, point));
            }
        }
        points = next;
    }
    Ok(points)
}

/// A swept value as it appears in variant names: a list's items joined by `-` (lists of lists
/// by `+`), so `grid_dim = [[6, 6], [8, 8]]` names its points `grid_dim=6-6` and `grid_dim=8-8`.
fn value_label(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Array(items) => {
            let sep = if list_depth(v) > 1 { "+" } else { "-" };
            items.iter().map(value_label).collect::<Vec<_>>().join(sep)
        }
        other => other.to_string(),
    }
}

/// Resolve one sweep point for one method: paper defaults, then the user's keys, then checks.
fn resolve(path: &Path, method: Method, point: &toml::Table) -> Result<RunSettings, ConfigError> {
    let p = || path.to_path_buf();
    let bad = |key: &str, message: String| ConfigError::BadValue {
        path: p(),
        key: key.to_string(),
        message,
    };
    // The domain first: `env_name` (Box Pushing when absent) takes the point's keys that are
    // its own, so its defaults may follow them (Box Pushing's horizon follows its grid).
    let env_name = match point.get("env_name") {
        Some(toml::Value::String(name)) => name.as_str(),
        Some(v) => return Err(bad("env_name", format!("expected a domain name, got {v}"))),
        None => "BP_MA",
    };
    let domain =
        crate::envs::registry::lookup(env_name).map_err(|e| bad("env_name", e.to_string()))?;
    let env = EnvSpec::from_keys_in(domain, point).map_err(|e| bad(e.key(), e.to_string()))?;
    let defaults = RunSettings::paper(env, method);
    let mut table = toml::Table::try_from(&defaults).expect("RunSettings serializes to a table");
    for (key, value) in point {
        if !table.contains_key(key) {
            // A key the domain knows and refuses (a MacroMARL kwarg its env does not read) is
            // refused with the domain's reason; any other is unknown.
            if let Err(e) = domain.keys(&toml::Table::from_iter([(key.clone(), value.clone())])) {
                if e.key == *key && e.message != NOT_A_KEY {
                    return Err(bad(key, format!("{}: {}", domain.name(), e.message)));
                }
            }
            return Err(ConfigError::UnknownKey {
                path: p(),
                key: key.clone(),
                method,
                hint: unknown_key_hint(key, method, &defaults.env, &table),
            });
        }
        // Accept integers where floats are expected (`l_rate = 1` means 1.0).
        let value = match (&table[key], value) {
            (toml::Value::Float(_), toml::Value::Integer(i)) => toml::Value::Float(*i as f64),
            _ => value.clone(),
        };
        if std::mem::discriminant(&table[key]) != std::mem::discriminant(&value) {
            return Err(bad(
                key,
                format!("expected {}, got {value}", table[key].type_str()),
            ));
        }
        // Every integer key is a count or a size: name the key instead of failing the whole
        // table's conversion below.
        if let toml::Value::Integer(i) = value {
            if i < 0 {
                return Err(bad(key, format!("must be >= 0, got {i}")));
            }
        }
        table.insert(key.clone(), value);
    }
    let config = RunSettings::from_table(method, table.clone()).map_err(|e| bad("config", e))?;
    // Bad values first, so `l_rate = nan` is named as a bad value, not as an unused key.
    validate(&config.config, method, &config.env).map_err(|(key, message)| bad(key, message))?;
    Ok(config)
}

/// What to say of `key`, which neither `method`'s family nor the domain has: the closest of
/// `known` (the run's keys: the family's and the domain's), and the family whose key it is when
/// it belongs to another one (`l_rate` for an actor-critic method).
fn unknown_key_hint(key: &str, method: Method, env: &EnvSpec, known: &toml::Table) -> String {
    let family = method.family().facts();
    let mut hint = String::new();
    if let Some(near) = closest_key(key, known.keys().map(String::as_str)) {
        hint.push_str(&format!("did you mean `{near}`? "));
    }
    let owner = Family::ALL
        .iter()
        .filter(|&&f| f != method.family())
        .find(|f| f.methods()[0].defaults(env).to_table().contains_key(key));
    if let Some(other) = owner {
        hint.push_str(&format!(
            "`{key}` is a key of {} ({}), not of {}; ",
            other.facts().description,
            other
                .methods()
                .iter()
                .map(|m| m.name())
                .collect::<Vec<_>>()
                .join(", "),
            family.description
        ));
    }
    let examples: Vec<String> = method
        .defaults(env)
        .to_table()
        .keys()
        .take(6)
        .cloned()
        .collect();
    hint.push_str(&format!(
        "{method} takes the keys of {}, e.g. {}",
        family.description,
        examples.join(", ")
    ));
    hint
}

/// The key of `known` nearest to `key` by edit distance, if it is within a third of the key's
/// length (a typo), or one contains the other (`lr` for `a_lr`).
fn closest_key<'a>(key: &str, known: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let limit = key.chars().count().div_ceil(3);
    known
        .map(|k| (edit_distance(key, k), k))
        .filter(|&(d, k)| d <= limit || (key.len() >= 2 && (k.contains(key) || key.contains(k))))
        .min()
        .map(|(_, k)| k)
}

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (prev + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            prev = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// Range checks that types cannot express, for the sizes of `env`'s environment (built once to
/// read them): the method's family's ([`Method::check`]). Returns the offending key and
/// why. The library entry point [`crate::train`] runs them too, so a config built in code is held
/// to the same rules.
pub fn validate(
    c: &RunConfig,
    method: Method,
    env: &EnvSpec,
) -> Result<(), (&'static str, String)> {
    let shape = EnvShape::of(env).map_err(|e| ("env_name", e.to_string()))?;
    method.check(c, &shape)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::value::method::ValueMethod;

    fn parse(text: &str, set: &[&str]) -> Result<Experiment, ConfigError> {
        let o = Overrides {
            set: set.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        };
        Experiment::parse(text, Path::new("test.toml"), "test", &o)
    }

    #[test]
    fn env_name_alone_gives_the_papers_bp10_setting() {
        let e = parse("methods = [\"our1\"]\n[params]\nenv_name = \"BP_MA\"", &[]).unwrap();
        let c = e.runs().unwrap()[0]
            .config
            .of::<ValueMethod>()
            .unwrap()
            .clone();
        assert_eq!((c.total_epi, c.trace_len, c.batch_size), (15000, 15, 128));
        assert_eq!((c.dec_rnn_h_size, c.cen_rnn_h_size), (32, 64));
        assert!(c.cen_explore && !c.h_explore && !c.sample_epi);
        assert_eq!(c.discount, 0.98);
    }

    #[test]
    fn dec_hddrqn_defaults_are_hysteretic_and_others_are_not() {
        let e = parse("methods = [\"dec-hddrqn\", \"cen-ddrqn\"]", &[]).unwrap();
        let runs = e.runs().unwrap();
        assert_eq!(
            (
                runs[0].config.of::<ValueMethod>().unwrap().init_h,
                runs[0].config.of::<ValueMethod>().unwrap().end_h
            ),
            (0.2, 0.4)
        );
        assert_eq!(
            (
                runs[1].config.of::<ValueMethod>().unwrap().init_h,
                runs[1].config.of::<ValueMethod>().unwrap().end_h
            ),
            (1.0, 1.0)
        );
    }

    #[test]
    fn set_overrides_file_values_and_reads_numbers() {
        let e = parse(
            "[params]\ntotal_epi = 100\n[method.our1]\ntotal_epi = 50",
            &["total_epi=300", "our1.l_rate=0.01"],
        )
        .unwrap();
        let c = e.runs().unwrap()[0]
            .config
            .of::<ValueMethod>()
            .unwrap()
            .clone();
        assert_eq!(c.total_epi, 300);
        assert_eq!(c.l_rate, 0.01);
    }

    #[test]
    fn a_set_value_with_a_line_break_is_refused_not_half_applied() {
        for set in [
            "total_epi=3\ngamma=0.5",
            "total_epi=3\r\nl_rate=0.1",
            "env_name=BP\nx",
        ] {
            let err = parse("", &[set]).unwrap_err().to_string();
            assert!(err.contains("line break"), "{set:?}: {err}");
        }
        // A TOML list written over two lines is still one value.
        let e = parse("methods = [\"our1\"]", &["grid_dim=[\n10]"]).unwrap();
        assert_eq!(e.runs().unwrap().len(), 1);
    }

    #[test]
    fn unknown_key_is_named_in_the_error() {
        let err = parse("[params]\ntotal_episodes = 5", &[]).unwrap_err();
        assert!(err.to_string().contains("`total_episodes`"), "{err}");
        let err = parse("", &["trace_lenn=3"]).unwrap_err();
        assert!(err.to_string().contains("`trace_lenn`"), "{err}");
    }

    #[test]
    fn bad_values_name_the_key() {
        for (set, key) in [
            ("batch_size=0", "batch_size"),
            ("l_rate=-1", "l_rate"),
            ("discount=1.5", "discount"),
            ("grid_dim=5", "grid_dim"),
            ("total_epi=\"many\"", "total_epi"),
        ] {
            let err = parse("", &[set]).unwrap_err();
            assert!(
                err.to_string().contains(&format!("`{key}`")),
                "{set}: {err}"
            );
        }
    }

    #[test]
    fn list_values_expand_into_named_variants() {
        let e = parse(
            "methods = [\"our1\"]\nseeds = [1, 2]\n[params]\ntrace_len = [10, 15]\nl_rate = [0.001, 0.01]",
            &[],
        )
        .unwrap();
        let runs = e.runs().unwrap();
        assert_eq!(runs.len(), 8);
        let mut names: Vec<_> = runs.iter().map(|r| r.curve_name()).collect();
        names.dedup();
        assert_eq!(names.len(), 4);
        assert!(
            names.contains(&"our1@l_rate=0.01,trace_len=15".to_string()),
            "{names:?}"
        );
        let r = runs
            .iter()
            .find(|r| r.variant == "l_rate=0.01,trace_len=10")
            .unwrap();
        let c = r.config.of::<ValueMethod>().unwrap();
        assert_eq!((c.trace_len, c.l_rate), (10, 0.01));
    }

    #[test]
    fn warehouse_defaults_follow_figure_5() {
        let e = parse(
            "methods = [\"our2\"]\n[params]\nenv_name = \"OSD_S_4\"",
            &[],
        )
        .unwrap();
        let c = e.runs().unwrap()[0]
            .config
            .of::<ValueMethod>()
            .unwrap()
            .clone();
        assert!(c.sample_epi && c.h_explore);
        assert_eq!((c.batch_size, c.train_freq, c.total_epi), (16, 30, 40000));
        assert_eq!(
            (c.l_rate, c.discount, c.replay_buffer_size),
            (0.0006, 1.0, 1000)
        );
    }

    #[test]
    fn a_domain_key_the_domain_does_not_use_is_refused_not_dropped() {
        let wtd = "methods = [\"our2\"]\n[params]\nenv_name = \"OSD_S_4\"";
        // The values every run records anyway are accepted (Warehouse runs record grid_dim = 10).
        parse(wtd, &["grid_dim=10", "tb_m_noisy=0.2"]).unwrap();
        let err = parse(wtd, &["grid_dim=30"]).unwrap_err().to_string();
        assert!(
            err.contains("`grid_dim`") && err.contains("OSD_S_4"),
            "{err}"
        );
        let err = parse("", &["tb_m_noisy=0.1"]).unwrap_err().to_string();
        assert!(
            err.contains("`tb_m_noisy`") && err.contains("BP_MA"),
            "{err}"
        );
        let err = parse(wtd, &["tb_m_noisy=-0.5"]).unwrap_err().to_string();
        assert!(err.contains("`tb_m_noisy`"), "{err}");
    }

    #[test]
    fn a_nan_is_a_bad_value_not_an_unused_key() {
        for (set, key) in [
            ("l_rate=nan", "`l_rate`"),
            ("discount=nan", "`discount`"),
            ("eps_end=nan", "`eps_end`"),
        ] {
            let err = parse("", &[set]).unwrap_err().to_string();
            assert!(
                err.contains(key) && !err.contains("does not use"),
                "{set}: {err}"
            );
        }
    }

    #[test]
    fn a_seed_beyond_the_largest_is_refused_when_the_config_is_read() {
        let err = parse("seeds = [0, 9223372036854775807]", &[]);
        assert!(err.is_ok(), "{err:?}");
        let o = Overrides {
            seeds: Some(vec![9_223_372_036_854_775_808]),
            ..Overrides::default()
        };
        let err = Experiment::parse("", Path::new("e.toml"), "e", &o)
            .unwrap_err()
            .to_string();
        assert!(err.contains("9223372036854775808"), "{err}");
    }

    #[test]
    fn env_name_aliases_resolve_to_the_reference_names() {
        let e = parse("[params]\nenv_name = \"box-pushing\"\ngrid_dim = 30", &[]).unwrap();
        let run = &e.runs().unwrap()[0];
        assert_eq!(run.env, crate::envs::box_pushing::paper_spec(30));
        let text = toml::to_string(&RunSettings {
            env: run.env.clone(),
            config: run.config.clone(),
        })
        .unwrap();
        assert!(
            text.starts_with("env_name = \"BP_MA\"\ngrid_dim = 30\n"),
            "{text}"
        );
    }

    #[test]
    fn our2_on_windows_is_refused() {
        let err = parse("methods = [\"our2\"]", &[]).unwrap_err();
        assert!(err.to_string().contains("sample_epi"), "{err}");
    }

    #[test]
    fn resolved_config_round_trips_through_toml() {
        let e = parse(default_experiment().0, &[]).unwrap();
        let run = &e.runs().unwrap()[0];
        let text = toml::to_string(&run.config.to_table()).unwrap();
        assert_eq!(
            run.method
                .config_from_table(toml::from_str(&text).unwrap())
                .unwrap(),
            run.config
        );
    }

    #[test]
    fn names_that_are_not_one_safe_path_component_are_refused() {
        for name in ["../../x", "/abs", "", "a\nb", "..", "a/b", "$(id)"] {
            let text = format!("name = {}", toml::Value::String(name.into()));
            let err = parse(&text, &[]).unwrap_err();
            assert!(
                matches!(err, ConfigError::BadName { .. }),
                "{name:?}: {err}"
            );
        }
        // The default name comes from the file name: a name with a space is refused too.
        let o = Overrides::default();
        let err = Experiment::parse("", Path::new("my exp.toml"), "my exp", &o).unwrap_err();
        assert!(err.to_string().contains("name = "), "{err}");
    }

    #[test]
    fn duplicate_runs_are_refused_naming_the_duplicate() {
        let err = parse("methods = [\"our1\", \"our1\"]", &[]).unwrap_err();
        assert!(err.to_string().contains("`our1` is listed twice"), "{err}");
        let err = parse("seeds = [1, 1]", &[]).unwrap_err();
        assert!(err.to_string().contains("seed 1 appears twice"), "{err}");
        for sweep in [
            "trace_len = [5, 5]",
            "l_rate = [0.001, 1e-3]",
            "l_rate = [1, 1.0]",
        ] {
            let err = parse(&format!("[params]\n{sweep}"), &[]).unwrap_err();
            assert!(
                matches!(err, ConfigError::DuplicatePoint { .. }),
                "{sweep}: {err}"
            );
        }
        let o = Overrides {
            methods: Some(vec![
                Method::Value(ValueMethod::Our1),
                Method::Value(ValueMethod::Our1),
            ]),
            ..Default::default()
        };
        assert!(Experiment::parse("", Path::new("t.toml"), "t", &o).is_err());
    }

    #[test]
    fn every_committed_experiment_runs_each_of_its_methods_alone() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
        let mut checked = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().and_then(|e| e.to_str()) != Some("toml") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let all = Experiment::parse(&text, &path, "x", &Overrides::default()).unwrap();
            for &m in &all.methods {
                let o = Overrides {
                    methods: Some(vec![m]),
                    ..Default::default()
                };
                let one = Experiment::parse(&text, &path, "x", &o)
                    .unwrap_or_else(|e| panic!("{} --methods {}: {e}", path.display(), m.name()));
                assert!(one.runs().unwrap().iter().all(|r| r.method == m));
                checked += 1;
            }
        }
        assert!(checked >= 10, "{checked}");
    }

    #[test]
    fn a_list_valued_key_is_one_value_and_its_list_of_lists_a_sweep() {
        let variants = |text: &str| -> Vec<(String, String)> {
            parse(text, &[])
                .unwrap()
                .runs()
                .unwrap()
                .into_iter()
                .map(|r| (r.variant, r.env.short_name()))
                .collect()
        };
        let head = "methods = [\"our1\"]\n[params]\nenv_name = \"BP-MA-v0\"\n";
        assert_eq!(
            variants(&format!("{head}grid_dim = [6, 6]")),
            [(String::new(), "bpma6".to_string())]
        );
        assert_eq!(
            variants(&format!("{head}grid_dim = [[6, 6], [8, 8]]")),
            [
                ("grid_dim=6-6".to_string(), "bpma6".to_string()),
                ("grid_dim=8-8".to_string(), "bpma8".to_string())
            ]
        );
        // Box Pushing's grid_dim is a number, so a list of numbers sweeps it.
        let icra = "methods = [\"our1\"]\n[params]\ngrid_dim = [8, 10]";
        assert_eq!(variants(icra).len(), 2);
        // A key MacroMARL's script passes to every BP/OSD env, which Box Pushing does not
        // read, is refused with the reason, not dropped.
        let err = parse(&format!("{head}TB_move_speed = 0.6"), &[])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("`TB_move_speed`") && err.contains("does not read it"),
            "{err}"
        );
        let err = parse(&format!("{head}grid_size = 6"), &[]).unwrap_err();
        assert!(err.to_string().contains("unknown key `grid_size`"), "{err}");
    }

    #[test]
    fn an_unknown_keys_hint_comes_from_the_methods_own_family() {
        // An ICRA key given to an actor-critic method: the hint names the family `l_rate` belongs
        // to and MacroMARL's learning rates among the method's own keys.
        let err = parse("methods = [\"mac-iac\"]\n[params]\nl_rate = 0.01", &[])
            .unwrap_err()
            .to_string();
        assert!(err.contains("unknown key `l_rate` for mac-iac"), "{err}");
        assert!(err.contains("a_lr, c_lr"), "{err}");
        assert!(err.contains("is a key of the ICRA 2020"), "{err}");
        assert!(!err.contains("e.g. total_epi, replay_buffer_size"), "{err}");
        // And the other way round.
        let err = parse("methods = [\"our1\"]\n[params]\na_lr = 0.01", &[])
            .unwrap_err()
            .to_string();
        assert!(err.contains("`a_lr` is a key of MacroMARL's"), "{err}");
        assert!(
            err.contains("our1 takes the keys of the ICRA 2020"),
            "{err}"
        );
        // A typo of the family's own key.
        let err = parse("methods = [\"our1\"]\n[params]\ntrace_lne = 3", &[])
            .unwrap_err()
            .to_string();
        assert!(err.contains("did you mean `trace_len`?"), "{err}");
        assert!(!err.contains("is a key of"), "{err}");
    }

    #[test]
    fn sweeps_are_bounded_and_never_empty() {
        let err = parse("[params]\ntrace_len = []", &[]).unwrap_err();
        assert!(
            err.to_string().contains("`trace_len`: an empty list"),
            "{err}"
        );
        // 10^12 points: refused from the list lengths alone, at once.
        let keys = [
            "trace_len",
            "batch_size",
            "train_freq",
            "eval_num_epi",
            "dec_mlp_layer_size",
            "dec_rnn_h_size",
            "cen_mlp_layer_size",
            "cen_rnn_h_size",
            "h_stable_at",
            "eps_l_d_steps",
            "target_update_freq",
            "sub_trace_len",
        ];
        let mut text = String::from("[params]\n");
        for k in keys {
            text.push_str(&format!("{k} = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n"));
        }
        let t0 = std::time::Instant::now();
        let err = parse(&text, &[]).unwrap_err();
        assert!(matches!(err, ConfigError::TooManyRuns { .. }), "{err}");
        assert!(t0.elapsed().as_secs() < 5);
    }

    #[test]
    fn sizes_beyond_their_bounds_name_the_key() {
        for (set, key) in [
            ("batch_size=100000000", "batch_size"),
            ("dec_rnn_h_size=1000000", "dec_rnn_h_size"),
            ("env_terminate_step=10000000000", "env_terminate_step"),
            ("grid_dim=100000", "grid_dim"),
        ] {
            let err = parse("", &[set]).unwrap_err();
            assert!(
                err.to_string().contains(&format!("`{key}`")),
                "{set}: {err}"
            );
        }
    }

    #[test]
    fn messages_name_the_real_problem() {
        let err = parse("[params]\ntotal_epi = -5", &[]).unwrap_err();
        assert!(
            err.to_string().contains("`total_epi`: must be >= 0"),
            "{err}"
        );
        let err = parse("", &["total_epi=99999999999999999999999"]).unwrap_err();
        assert!(
            err.to_string()
                .contains("not a number this config can hold"),
            "{err}"
        );
        let err = parse("", &["our9.l_rate=1"]).unwrap_err();
        assert!(err.to_string().contains("our9"), "{err}");
        assert!(!err.to_string().contains("expected key=value"), "{err}");
        for (set, key) in [
            ("grid_dim=11", "grid_dim"),
            ("start_train=0", "start_train"),
            ("discount=0", "discount"),
            ("total_epi=105", "total_epi"),
        ] {
            let err = parse("", &[set]).unwrap_err();
            assert!(
                err.to_string().contains(&format!("`{key}`")),
                "{set}: {err}"
            );
        }
    }

    #[test]
    fn a_typo_in_an_unselected_methods_section_is_an_error() {
        let err = parse(
            "methods = [\"our1\"]\n[method.dec-hddrqn]\ninit_hh = 0.2",
            &[],
        )
        .unwrap_err();
        assert!(err.to_string().contains("`init_hh`"), "{err}");
    }
}
