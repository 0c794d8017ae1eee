//! `macdec import`: a policy directory from the references' PyTorch state_dicts.

use crate::experiment::definition::limits;
use anyhow::{bail, Context, Result};
use clap::ValueEnum;
use std::path::PathBuf;

use super::bounds::bounded_count;

/// Whose trained nets `macdec import` reads.
#[derive(Clone, Copy, ValueEnum)]
enum ImportReference {
    /// The ICRA code's DDRQN Q-nets (`--env box-pushing` or `warehouse`).
    Icra,
    /// MacroMARL's GRU actors (`--env` a gym id such as `BP-MA-v0`, `--params`).
    Macromarl,
    /// ACAC's actors with their time tables (`--env` ACAC's gym id: `BP-MA-v0`,
    /// `Overcooked-MA-v1`, `Overcooked-MA-v0`; `--params`).
    Acac,
}

#[derive(clap::Args)]
pub(super) struct ImportArgs {
    /// Whose nets: the ICRA code's Q-nets, MacroMARL's actors or ACAC's.
    #[arg(long, value_enum, default_value = "icra")]
    reference: ImportReference,
    /// The domain the policy was trained on: `box-pushing` or `warehouse` (icra); the gym id,
    /// e.g. `BP-MA-v0`, `OSD-T-v0`, `Overcooked-MA-v1` (macromarl); ACAC's gym id (acac:
    /// `Overcooked-MA-v1` is then ACAC's own copy of the kitchen).
    #[arg(long)]
    env: String,
    /// MacroMARL and ACAC: a JSON object of the reference's keyword arguments for `gym.make` (e.g.
    /// `{"grid_dim": [14, 14]}`); the published values where absent.
    #[arg(long)]
    params: Option<PathBuf>,
    /// ICRA Box Pushing grid size N (N x N); the paper uses 10 and 30.
    #[arg(long, value_parser = |t: &str| bounded_count(t, limits::MAX_GRID_DIM))]
    grid: Option<usize>,
    /// Episode length in primitive steps (ICRA paper: Box Pushing 100 on 10x10, 200 on 30x30,
    /// Warehouse 150; required for icra). MacroMARL: the published horizon by default.
    #[arg(long, value_parser = |t: &str| bounded_count(t, limits::MAX_HORIZON))]
    horizon: Option<usize>,
    /// ICRA Warehouse: std of the Turtlebots' movement noise (paper 0). With --reference
    /// macromarl it is the domain's `tb_m_noisy` key, refused by domains without one.
    #[arg(long)]
    tb_m_noisy: Option<f64>,
    /// Comma-separated state_dict safetensors files, one per agent, in agent order.
    #[arg(long, value_delimiter = ',', required = true)]
    agents: Vec<PathBuf>,
    /// Discount per primitive step of the reported return (default: the paper's, e.g. Box
    /// Pushing 0.98, Warehouse 1.0).
    #[arg(long)]
    discount: Option<f64>,
    /// The policy directory to write.
    #[arg(long)]
    out: PathBuf,
}

/// Build the policy directory from the reference's state_dicts and say what was imported.
pub(super) fn run(args: ImportArgs) -> Result<()> {
    use crate::deploy::policy::import::{import_policy, ImportRequest};
    use crate::deploy::policy::import_acac::import_acac_actors;
    use crate::deploy::policy::import_actors::import_actors;
    let env = import_env(&args)?;
    let request = ImportRequest {
        discount: args
            .discount
            .or_else(|| env.paper_discount())
            .unwrap_or(1.0),
        env,
        agents: args.agents,
    };
    let manifest = match args.reference {
        ImportReference::Icra => import_policy(&request, &args.out),
        ImportReference::Macromarl => import_actors(&request, &args.out),
        ImportReference::Acac => import_acac_actors(&request, &args.out),
    }
    .with_context(|| format!("importing into {}", args.out.display()))?;
    let arch = &manifest.nets[0].architecture;
    eprintln!(
        "imported {} agent(s) of {} ({} {} / {}, discount {}) to {}",
        manifest.agents.len(),
        manifest.env.name(),
        arch.kind,
        arch.mlp_out_size
            .map_or(arch.mlp_layer_size.to_string(), |m1| format!(
                "[{}, {m1}]",
                arch.mlp_layer_size
            )),
        arch.rnn_h_size,
        manifest.discount,
        args.out.display()
    );
    Ok(())
}

/// The domain `macdec import` names: ICRA's by `--env`, `--grid`, `--horizon`, `--tb-m-noisy`;
/// MacroMARL's and ACAC's by the gym id, `--params` (the reference's keyword arguments) and
/// `--horizon`.
fn import_env(args: &ImportArgs) -> Result<crate::envs::EnvSpec> {
    use crate::envs::domain::{json_to_toml, key_table, HORIZON_KEY};
    use crate::envs::EnvSpec;
    let horizon = |h: usize| (HORIZON_KEY, toml::Value::from(h as i64));
    match args.reference {
        ImportReference::Icra => {
            let Some(h) = args.horizon else {
                bail!("--reference icra needs --horizon (the episode length in primitive steps)")
            };
            if args.params.is_some() {
                bail!("--params is for --reference macromarl or acac");
            }
            Ok(match (args.env.as_str(), args.grid) {
                ("box-pushing", Some(grid)) => EnvSpec::new(
                    "box-pushing",
                    &key_table([
                        ("grid_dim", (grid as i64).into()),
                        horizon(h),
                        // Refused unless 0: Box Pushing has no noise to set.
                        ("tb_m_noisy", args.tb_m_noisy.unwrap_or(0.0).into()),
                    ]),
                ),
                ("box-pushing", None) => bail!("--env box-pushing needs --grid N"),
                ("warehouse", None) => EnvSpec::new(
                    "warehouse",
                    &key_table([
                        horizon(h),
                        ("tb_m_noisy", args.tb_m_noisy.unwrap_or(0.0).into()),
                    ]),
                ),
                ("warehouse", Some(_)) => bail!("--grid is for box-pushing; warehouse has none"),
                (other, _) => {
                    bail!("--reference icra: --env must be box-pushing or warehouse, got `{other}`")
                }
            }?)
        }
        ImportReference::Macromarl | ImportReference::Acac => {
            if args.grid.is_some() {
                bail!("--grid is for --reference icra; the grid is `grid_dim` in --params");
            }
            let domain = match args.reference {
                ImportReference::Acac => {
                    crate::envs::acac::domain_of(&args.env).with_context(|| {
                        let ids: Vec<&str> =
                            crate::envs::acac::GYM_IDS.iter().map(|(g, _)| *g).collect();
                        format!(
                            "--reference acac: `{}` is not a gym id ACAC's runner builds ({})",
                            args.env,
                            ids.join(", ")
                        )
                    })?
                }
                _ => args.env.as_str(),
            };
            let mut given = toml::Table::new();
            if let Some(path) = &args.params {
                let text = crate::files::bounded_read::read_regular_file(path, 1 << 20)
                    .with_context(|| format!("reading {}", path.display()))?;
                let value: serde_json::Value = serde_json::from_slice(&text)
                    .with_context(|| format!("parsing {}", path.display()))?;
                let serde_json::Value::Object(map) = value else {
                    bail!(
                        "{}: expected a JSON object of keyword arguments",
                        path.display()
                    );
                };
                for (k, v) in map {
                    let v = json_to_toml(&v)
                        .with_context(|| format!("{}: `{k}` holds a null", path.display()))?;
                    given.insert(k, v);
                }
            }
            if let Some(h) = args.horizon {
                given.insert(HORIZON_KEY.into(), (h as i64).into());
            }
            if let Some(noise) = args.tb_m_noisy {
                given.insert("tb_m_noisy".into(), noise.into());
            }
            Ok(EnvSpec::new(domain, &given)?)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    /// `import --agents a.safetensors --out o` with `flags`.
    fn parse(flags: &[&str]) -> ImportArgs {
        let argv = [&["--agents", "a.safetensors", "--out", "o"], flags].concat();
        match accepted("import", &argv) {
            Command::Import(args) => args,
            _ => unreachable!("`import` parses as Command::Import"),
        }
    }

    fn refused(flags: &[&str], kind: ErrorKind, message: &str) {
        let argv = [&["--agents", "a.safetensors", "--out", "o"], flags].concat();
        assert_refused("import", &argv, kind, message);
    }

    /// The message `import_env` fails with for these flags.
    fn env_error(flags: &[&str]) -> String {
        match import_env(&parse(flags)) {
            Ok(spec) => panic!("{flags:?} named a domain: {}", spec.name()),
            Err(e) => format!("{e:#}"),
        }
    }

    #[test]
    fn import_reads_the_icra_reference_by_default() {
        let args = parse(&["--env", "warehouse"]);
        assert!(matches!(args.reference, ImportReference::Icra));
        assert_eq!(args.env, "warehouse");
        assert_eq!(args.agents, [PathBuf::from("a.safetensors")]);
        assert_eq!(args.out, PathBuf::from("o"));
        assert_eq!((args.params, args.grid, args.horizon), (None, None, None));
        assert_eq!(args.tb_m_noisy, None);
        assert_eq!(args.discount, None);
        let args = parse(&["--env", "BP-MA-v0", "--reference", "macromarl"]);
        assert!(matches!(args.reference, ImportReference::Macromarl));
        refused(
            &["--env", "x", "--reference", "pymarl"],
            ErrorKind::InvalidValue,
            "'pymarl'",
        );
    }

    #[test]
    fn import_needs_env_agents_and_out() {
        let missing = ErrorKind::MissingRequiredArgument;
        assert_refused(
            "import",
            &["--env", "warehouse", "--out", "o"],
            missing,
            "--agents <AGENTS>",
        );
        assert_refused(
            "import",
            &["--agents", "a", "--out", "o"],
            missing,
            "--env <ENV>",
        );
        assert_refused(
            "import",
            &["--env", "warehouse", "--agents", "a"],
            missing,
            "--out <OUT>",
        );
        let argv = [
            "--env",
            "warehouse",
            "--agents",
            "a0.st,a1.st",
            "--out",
            "o",
        ];
        let Command::Import(args) = accepted("import", &argv) else {
            unreachable!("`import` parses as Command::Import")
        };
        assert_eq!(
            args.agents,
            [PathBuf::from("a0.st"), PathBuf::from("a1.st")]
        );
    }

    #[test]
    fn import_grid_and_horizon_are_bounded_like_a_config() {
        let v = ErrorKind::ValueValidation;
        assert_eq!(parse(&["--env", "e", "--grid", "1000"]).grid, Some(1000));
        refused(&["--env", "e", "--grid", "0"], v, "must be at least 1");
        refused(
            &["--env", "e", "--grid", "1001"],
            v,
            "must be at most 1000, got 1001",
        );
        assert_eq!(
            parse(&["--env", "e", "--horizon", "100000"]).horizon,
            Some(100_000)
        );
        refused(&["--env", "e", "--horizon", "0"], v, "must be at least 1");
        refused(
            &["--env", "e", "--horizon", "100001"],
            v,
            "must be at most 100000, got 100001",
        );
    }

    #[test]
    fn icra_imports_name_box_pushing_by_grid_and_warehouse_without_one() {
        let spec = import_env(&parse(&[
            "--env",
            "box-pushing",
            "--grid",
            "10",
            "--horizon",
            "100",
        ]))
        .unwrap();
        assert_eq!(spec.name(), "box-pushing");
        let spec = import_env(&parse(&["--env", "warehouse", "--horizon", "150"])).unwrap();
        assert_eq!(spec.name(), "warehouse");
    }

    #[test]
    fn icra_imports_refuse_what_the_reference_cannot_have() {
        assert_eq!(
            env_error(&["--env", "box-pushing", "--grid", "10"]),
            "--reference icra needs --horizon (the episode length in primitive steps)"
        );
        assert_eq!(
            env_error(&["--env", "warehouse", "--horizon", "9", "--params", "p.json"]),
            "--params is for --reference macromarl or acac"
        );
        assert_eq!(
            env_error(&["--env", "box-pushing", "--horizon", "100"]),
            "--env box-pushing needs --grid N"
        );
        assert_eq!(
            env_error(&["--env", "warehouse", "--horizon", "150", "--grid", "3"]),
            "--grid is for box-pushing; warehouse has none"
        );
        assert_eq!(
            env_error(&["--env", "BP-MA-v0", "--horizon", "100"]),
            "--reference icra: --env must be box-pushing or warehouse, got `BP-MA-v0`"
        );
        // Box Pushing has no noise: --tb-m-noisy other than 0 is refused, not dropped.
        let bp = ["--env", "box-pushing", "--grid", "10", "--horizon", "100"];
        assert!(env_error(&[&bp[..], &["--tb-m-noisy", "0.2"]].concat()).contains("`tb_m_noisy`"));
        import_env(&parse(&[&bp[..], &["--tb-m-noisy", "0"]].concat())).unwrap();
    }

    #[test]
    fn macromarl_imports_take_keyword_arguments_as_a_json_object() {
        let mm = ["--reference", "macromarl", "--env", "BP-MA-v0"];
        assert_eq!(
            env_error(&[&mm[..], &["--grid", "6"]].concat()),
            "--grid is for --reference icra; the grid is `grid_dim` in --params"
        );
        let dir = tempfile::tempdir().unwrap();
        let params = dir.path().join("params.json");
        let p = params.to_str().unwrap();
        std::fs::write(&params, "[6, 6]").unwrap();
        assert_eq!(
            env_error(&[&mm[..], &["--params", p]].concat()),
            format!("{p}: expected a JSON object of keyword arguments")
        );
        std::fs::write(&params, r#"{"grid_dim": null}"#).unwrap();
        assert!(env_error(&[&mm[..], &["--params", p]].concat())
            .starts_with(&format!("{p}: `grid_dim` holds a null")));
        std::fs::write(&params, r#"{"grid_dim": [6, 6]}"#).unwrap();
        let spec = import_env(&parse(&[&mm[..], &["--params", p]].concat())).unwrap();
        assert_eq!(spec.name(), "BP-MA-v0");
    }
}
