//! A training run's nets as a policy directory: `<run>/policy/` holds one safetensors file per
//! net with the reference's PyTorch state_dict names (`dec_agent_0.safetensors`, ...,
//! `cen.safetensors`) and `policy.json`, written with every checkpoint. `checkpoint.bin` (the
//! whole trainer) is for resuming only; `export` and `render` read these files, so a run stays
//! usable after the trainer's serialized form changes. Nothing here knows a learner: it takes
//! and returns plain nets.

use super::error::PolicyError;
use super::manifest::{AgentLayout, Manifest, NetFile, NetKind, NetRole, RunInfo, POLICY_FILE};
use super::policy_env::PolicyEnv;
use crate::nn::{GruActor, QNet};
use std::path::Path;

/// The policy directory inside a run directory.
pub const POLICY_DIR: &str = "policy";
/// The file name of agent `agent`'s decentralized net in a run's policy directory.
pub fn dec_file_name(agent: usize) -> String {
    format!("dec_agent_{agent}.safetensors")
}
/// The file name of the centralized net in a run's policy directory.
pub const CEN_FILE: &str = "cen.safetensors";

/// A policy directory's Q-nets as read back, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyNets {
    /// The description they were read by.
    pub manifest: Manifest,
    /// Agent i's decentralized net is `dec[i]` (empty for Cen-DDRQN).
    pub dec: Vec<QNet>,
    /// The centralized net, if the method has one.
    pub cen: Option<QNet>,
}

/// Write `run_dir/policy/` (see the module doc): the decentralized nets `dec` (agent order) and
/// the centralized net `cen`, for a domain of layout `agents`.
#[allow(clippy::too_many_arguments)]
pub fn write_policy_files(
    run_dir: &Path,
    env: PolicyEnv,
    agents: Vec<AgentLayout>,
    discount: f64,
    evaluated: NetRole,
    run: RunInfo,
    dec: &[&QNet],
    cen: Option<&QNet>,
) -> Result<Manifest, PolicyError> {
    let nets: Vec<NetFile> = dec
        .iter()
        .enumerate()
        .map(|(i, n)| NetFile::qnet(NetRole::Dec, Some(i), dec_file_name(i), n))
        .chain(cen.map(|n| NetFile::qnet(NetRole::Cen, None, CEN_FILE.to_string(), n)))
        .collect();
    let dir = run_dir.join(POLICY_DIR);
    Manifest::write_new(&dir, env, agents, discount, evaluated, run, &nets)
}

/// Write an actor-critic run's actors as its policy files (`run_dir/policy/`): agent i's actor
/// as [`dec_file_name`] (the evaluated nets), or Mac-CAC's one centralized actor as
/// [`CEN_FILE`], kind `actor`.
pub fn write_actor_policy_files(
    run_dir: &Path,
    env: PolicyEnv,
    agents: Vec<AgentLayout>,
    discount: f64,
    run: RunInfo,
    actors: &[&GruActor],
    centralized: bool,
) -> Result<Manifest, PolicyError> {
    let (evaluated, nets): (NetRole, Vec<NetFile>) = if centralized {
        let nets = actors
            .iter()
            .map(|n| NetFile::actor(NetRole::Cen, None, CEN_FILE.to_string(), n))
            .collect();
        (NetRole::Cen, nets)
    } else {
        let nets = actors
            .iter()
            .enumerate()
            .map(|(i, n)| NetFile::actor(NetRole::Dec, Some(i), dec_file_name(i), n))
            .collect();
        (NetRole::Dec, nets)
    };
    let dir = run_dir.join(POLICY_DIR);
    Manifest::write_new(&dir, env, agents, discount, evaluated, run, &nets)
}

/// Read a run's policy files (`run_dir/policy/`, of any format version this build reads): the
/// description and every Q-net, each checked.
pub fn read_policy_files(run_dir: &Path) -> Result<PolicyNets, PolicyError> {
    let dir = run_dir.join(POLICY_DIR);
    if !dir.join(POLICY_FILE).exists() {
        return Err(PolicyError::MissingRun {
            dir: run_dir.to_path_buf(),
        });
    }
    read_qnets(&dir)
}

/// Read every Q-net of the policy directory `dir` (a run's `policy/` or an export), checked.
pub fn read_qnets(dir: &Path) -> Result<PolicyNets, PolicyError> {
    let manifest = Manifest::read(dir)?;
    let mut dec = Vec::new();
    let mut cen = None;
    for agent in 0..manifest.agents.len() {
        match manifest.agent_net(agent) {
            Ok(index) => dec.push(manifest.load_qnet(dir, index)?),
            Err(PolicyError::NoAgentNet { .. }) if agent == 0 => break,
            Err(e) => return Err(e),
        }
    }
    let cen_index = manifest
        .nets
        .iter()
        .position(|n| n.kind == NetKind::Q && n.role == NetRole::Cen);
    if let Some(index) = cen_index {
        cen = Some(manifest.load_qnet(dir, index)?);
    }
    Ok(PolicyNets { manifest, dec, cen })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::{EnvSpec, MacroEnv};
    use crate::nn::QNetConfig;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn bp8() -> EnvSpec {
        crate::envs::box_pushing::spec(8, 20)
    }

    fn run_info() -> RunInfo {
        RunInfo {
            experiment: "t".into(),
            method: "our1".into(),
            variant: String::new(),
            seed: 7,
            episodes_trained: 40,
            config: serde_json::json!({"lr": 0.001}),
        }
    }

    fn nets() -> (Vec<QNet>, QNet) {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let cfg = |input, output| QNetConfig {
            input,
            mlp: 6,
            hidden: 5,
            output,
        };
        let dec = (0..2).map(|_| QNet::new(cfg(5, 8), &mut rng)).collect();
        (dec, QNet::new(cfg(10, 64), &mut rng))
    }

    fn write(
        run_dir: &Path,
        evaluated: NetRole,
        dec: &[QNet],
        cen: Option<&QNet>,
    ) -> Result<Manifest, PolicyError> {
        let domain = bp8().build().unwrap();
        let refs: Vec<&QNet> = dec.iter().collect();
        let agents = AgentLayout::of_domain(&domain);
        write_policy_files(
            run_dir,
            bp8().into(),
            agents,
            0.98,
            evaluated,
            run_info(),
            &refs,
            cen,
        )
    }

    #[test]
    fn written_files_read_back_as_the_same_nets() {
        let dir = tempfile::tempdir().unwrap();
        let (dec, cen) = nets();
        let written = write(dir.path(), NetRole::Dec, &dec, Some(&cen)).unwrap();
        let p = dir.path().join(POLICY_DIR);
        for f in [
            "dec_agent_0.safetensors",
            "dec_agent_1.safetensors",
            CEN_FILE,
            POLICY_FILE,
        ] {
            assert!(p.join(f).is_file(), "{f}");
        }
        let back = read_policy_files(dir.path()).unwrap();
        assert_eq!(back.dec, dec);
        assert_eq!(back.cen, Some(cen));
        assert_eq!(back.manifest, written);
        assert_eq!(back.manifest.run, run_info());
        assert_eq!(back.manifest.agents[1].action_names.len(), 8);
        let cen_entry = &back.manifest.nets[2];
        assert_eq!(
            (
                cen_entry.role,
                cen_entry.agent,
                cen_entry.input,
                cen_entry.output
            ),
            (NetRole::Cen, None, 10, 64)
        );
    }

    #[test]
    fn a_centralized_net_must_read_the_joint_layout() {
        let dir = tempfile::tempdir().unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let cfg = QNetConfig {
            input: 10,
            mlp: 3,
            hidden: 3,
            output: 63,
        };
        let err = write(
            dir.path(),
            NetRole::Cen,
            &[],
            Some(&QNet::new(cfg, &mut rng)),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("says 10 and 64"), "{err}");
    }

    #[test]
    fn a_changed_weight_file_or_a_newer_version_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let (dec, _) = nets();
        write(dir.path(), NetRole::Dec, &dec, None).unwrap();
        let p = dir.path().join(POLICY_DIR);
        std::fs::copy(p.join(dec_file_name(0)), p.join(dec_file_name(1))).unwrap();
        let err = read_policy_files(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("dec_agent_1.safetensors") && err.contains("SHA-256"),
            "{err}"
        );

        let json = p.join(POLICY_FILE);
        let text = std::fs::read_to_string(&json).unwrap();
        std::fs::write(
            &json,
            text.replace("\"format_version\": 2", "\"format_version\": 9"),
        )
        .unwrap();
        let err = read_policy_files(dir.path()).unwrap_err().to_string();
        assert!(err.contains("format_version 9"), "{err}");
        std::fs::write(
            &json,
            text.replace("dec_agent_1.safetensors", "../x.safetensors"),
        )
        .unwrap();
        let err = read_policy_files(dir.path()).unwrap_err().to_string();
        assert!(err.contains("plain file name"), "{err}");
    }

    #[test]
    fn a_centralized_only_policy_reads_back_without_decentralized_nets() {
        let dir = tempfile::tempdir().unwrap();
        let (_, cen) = nets();
        write(dir.path(), NetRole::Cen, &[], Some(&cen)).unwrap();
        let back = read_policy_files(dir.path()).unwrap();
        assert_eq!(back.cen, Some(cen));
        assert!(back.dec.is_empty());
        let err = back.manifest.verify_agent(&dir.path().join(POLICY_DIR), 0);
        assert!(matches!(err, Err(PolicyError::NoAgentNet { agent: 0, .. })));
    }

    #[test]
    fn a_run_without_policy_files_gets_an_error_saying_so() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_policy_files(dir.path()).unwrap_err().to_string();
        assert!(err.contains("has no policy/policy.json"), "{err}");
    }

    #[test]
    fn a_layout_of_another_agent_count_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (dec, _) = nets();
        let domain = bp8().build().unwrap();
        let mut agents = AgentLayout::of_domain(&domain);
        agents.pop();
        let refs: Vec<&QNet> = dec.iter().collect();
        let err = write_policy_files(
            dir.path(),
            bp8().into(),
            agents,
            0.98,
            NetRole::Dec,
            run_info(),
            &refs,
            None,
        )
        .unwrap_err();
        assert!(
            matches!(
                err,
                PolicyError::AgentCount {
                    expected: 2,
                    got: 1,
                    ..
                }
            ),
            "{err}"
        );
        assert_eq!(domain.n_agents(), 2);
    }
}
