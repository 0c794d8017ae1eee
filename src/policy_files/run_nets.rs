//! A training run's nets as a policy directory: `<run>/policy/` holds one safetensors file per
//! net with the reference's PyTorch state_dict names (`dec_agent_0.safetensors`, ...,
//! `cen.safetensors`) and `policy.json`, written with every checkpoint. `checkpoint.bin` (the
//! whole trainer) is for resuming only; `export` and `render` read these files, so a run stays
//! usable after the trainer's serialized form changes. Nothing here knows a learner or a method
//! family: it takes a list of nets, each saying its kind, role and agent ([`SavedNet`]), and
//! returns plain nets.

use super::error::PolicyError;
use super::manifest::{AgentLayout, Manifest, NetFile, NetKind, NetRole, RunInfo, POLICY_FILE};
use super::policy_env::PolicyEnv;
use crate::nn::{ActingNet, ActingNetRef};
use std::path::Path;

/// The policy directory inside a run directory.
pub const POLICY_DIR: &str = "policy";
/// The file name of agent `agent`'s decentralized net in a run's policy directory.
pub fn dec_file_name(agent: usize) -> String {
    format!("dec_agent_{agent}.safetensors")
}
/// The file name of the centralized net in a run's policy directory.
pub const CEN_FILE: &str = "cen.safetensors";

/// One net a training run saves, as its learner hands it over: the net (its kind follows: a
/// Q-net or an actor), whose it is (one agent's, or the team's centralized net) and whether it
/// is part of the policy the run's evaluations ran. The writer ([`write_policy_files`]) and the
/// readers need nothing else, so they never ask which method family trained the run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SavedNet<'a> {
    /// The net.
    pub net: ActingNetRef<'a>,
    /// Decentralized (one agent's) or centralized (the team's).
    pub role: NetRole,
    /// The agent of a decentralized net; `None` for a centralized one.
    pub agent: Option<usize>,
    /// Whether the run's evaluations act with this net.
    pub evaluated: bool,
}

impl<'a> SavedNet<'a> {
    /// Agent `agent`'s own net.
    pub fn agent(agent: usize, net: ActingNetRef<'a>, evaluated: bool) -> Self {
        SavedNet {
            net,
            role: NetRole::Dec,
            agent: Some(agent),
            evaluated,
        }
    }

    /// The team's centralized net (it reads the joint observation and scores joint
    /// macro-actions).
    pub fn team(net: ActingNetRef<'a>, evaluated: bool) -> Self {
        SavedNet {
            net,
            role: NetRole::Cen,
            agent: None,
            evaluated,
        }
    }

    /// What the net computes.
    pub fn kind(&self) -> NetKind {
        match self.net {
            ActingNetRef::Q(_) => NetKind::Q,
            ActingNetRef::Actor(_) | ActingNetRef::Acac(..) => NetKind::Actor,
        }
    }

    /// Its file in a run's policy directory: [`dec_file_name`] of its agent, or [`CEN_FILE`].
    pub fn file_name(&self) -> String {
        match self.agent {
            Some(agent) => dec_file_name(agent),
            None => CEN_FILE.to_string(),
        }
    }

    /// Its entry and weights, as written.
    pub fn net_file(&self) -> NetFile {
        let file = self.file_name();
        match self.net {
            ActingNetRef::Q(q) => NetFile::qnet(self.role, self.agent, file, q),
            ActingNetRef::Actor(a) => NetFile::actor(self.role, self.agent, file, a),
            ActingNetRef::Acac(..) => {
                NetFile::acting(self.role, self.agent, file, &self.net.to_net())
            }
        }
    }
}

/// The role of the evaluated nets of `nets` (what `policy.json`'s `evaluated` records): every
/// net marked evaluated must share it, and at least one must be marked.
fn evaluated_role(nets: &[SavedNet<'_>]) -> Result<NetRole, PolicyError> {
    let mut roles = nets.iter().filter(|n| n.evaluated).map(|n| n.role);
    let invalid =
        |reason: String| PolicyError::invalid(Path::new(POLICY_FILE), "evaluated", reason);
    let first = roles
        .next()
        .ok_or_else(|| invalid("no saved net is marked as the evaluated policy".into()))?;
    if roles.any(|r| r != first) {
        return Err(invalid(
            "the evaluated policy mixes decentralized and centralized nets; it must be one or the other".into(),
        ));
    }
    Ok(first)
}

/// Write `run_dir/policy/` (see the module doc): every net of `nets`, whatever its kind and
/// role, as its [`SavedNet::file_name`], for a domain of layout `agents`; `evaluated` records
/// the role of the nets marked evaluated.
pub fn write_policy_files(
    run_dir: &Path,
    env: PolicyEnv,
    agents: Vec<AgentLayout>,
    discount: f64,
    run: RunInfo,
    nets: &[SavedNet<'_>],
) -> Result<Manifest, PolicyError> {
    let evaluated = evaluated_role(nets)?;
    let files: Vec<NetFile> = nets.iter().map(SavedNet::net_file).collect();
    let dir = run_dir.join(POLICY_DIR);
    Manifest::write_new(&dir, env, agents, discount, evaluated, run, &files)
}

/// A policy directory's acting nets as read back, checked: what [`write_policy_files`] wrote,
/// or an export's, an import's or a version-1 run's.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyNets {
    /// The description they were read by.
    pub manifest: Manifest,
    /// Agent i's decentralized net (a Q-net or an actor) is `agents[i]`; empty when the policy
    /// has none (Cen-DDRQN, Mac-CAC).
    pub agents: Vec<ActingNet>,
    /// The centralized net that acts for the team (a Q-net or Mac-CAC's actor), if there is one.
    pub team: Option<ActingNet>,
}

/// Read a run's policy files (`run_dir/policy/`, of any format version this build reads): the
/// description and every acting net, each checked.
pub fn read_policy_files(run_dir: &Path) -> Result<PolicyNets, PolicyError> {
    let dir = run_dir.join(POLICY_DIR);
    if !dir.join(POLICY_FILE).exists() {
        return Err(PolicyError::MissingRun {
            dir: run_dir.to_path_buf(),
        });
    }
    read_nets(&dir)
}

/// Read every acting net of the policy directory `dir` (a run's `policy/` or an export), checked.
pub fn read_nets(dir: &Path) -> Result<PolicyNets, PolicyError> {
    let manifest = Manifest::read(dir)?;
    let mut agents = Vec::new();
    for agent in 0..manifest.agents.len() {
        match manifest.agent_net(agent) {
            Ok(index) => agents.push(manifest.load_acting_net(dir, index)?),
            Err(PolicyError::NoAgentNet { .. }) if agent == 0 => break,
            Err(e) => return Err(e),
        }
    }
    let team = match manifest.cen_net() {
        Some(index) => Some(manifest.load_acting_net(dir, index)?),
        None => None,
    };
    Ok(PolicyNets {
        manifest,
        agents,
        team,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::{EnvSpec, MacroEnv};
    use crate::nn::{QNet, QNetConfig};
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

    /// The run's nets as its learner hands them over: `dec` per agent, then `cen`; the nets of
    /// role `evaluated` are marked evaluated.
    fn saved<'a>(evaluated: NetRole, dec: &'a [QNet], cen: Option<&'a QNet>) -> Vec<SavedNet<'a>> {
        let is_dec = evaluated == NetRole::Dec;
        dec.iter()
            .enumerate()
            .map(|(i, n)| SavedNet::agent(i, ActingNetRef::Q(n), is_dec))
            .chain(cen.map(|n| SavedNet::team(ActingNetRef::Q(n), !is_dec)))
            .collect()
    }

    fn write(
        run_dir: &Path,
        evaluated: NetRole,
        dec: &[QNet],
        cen: Option<&QNet>,
    ) -> Result<Manifest, PolicyError> {
        let domain = bp8().build().unwrap();
        let agents = AgentLayout::of_domain(&domain);
        let nets = saved(evaluated, dec, cen);
        write_policy_files(run_dir, bp8().into(), agents, 0.98, run_info(), &nets)
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
        let q = |n: &QNet| ActingNet::Q(n.clone());
        assert_eq!(back.agents, dec.iter().map(q).collect::<Vec<_>>());
        assert_eq!(back.team, Some(q(&cen)));
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
        assert_eq!(back.team, Some(ActingNet::Q(cen)));
        assert!(back.agents.is_empty());
        let err = back.manifest.verify_agent(&dir.path().join(POLICY_DIR), 0);
        assert!(matches!(err, Err(PolicyError::NoAgentNet { agent: 0, .. })));
    }

    #[test]
    fn actors_are_written_and_read_back_by_the_same_writer_as_q_nets() {
        use crate::nn::{GruActor, GruActorConfig};
        let dir = tempfile::tempdir().unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let actor = |input, output, rng: &mut ChaCha8Rng| {
            let cfg = GruActorConfig {
                input,
                mlp: [6, 4],
                hidden: 5,
                output,
            };
            GruActor::new(cfg, rng)
        };
        let domain = bp8().build().unwrap();
        let layout = || AgentLayout::of_domain(&domain);
        // Decentralized actors, evaluated.
        let dec: Vec<GruActor> = (0..2).map(|_| actor(5, 8, &mut rng)).collect();
        let nets: Vec<SavedNet> = dec
            .iter()
            .enumerate()
            .map(|(i, a)| SavedNet::agent(i, ActingNetRef::Actor(a), true))
            .collect();
        let run = dir.path().join("iac");
        let written =
            write_policy_files(&run, bp8().into(), layout(), 0.98, run_info(), &nets).unwrap();
        assert_eq!(written.evaluated, NetRole::Dec);
        assert!(written.nets.iter().all(|n| n.kind == NetKind::Actor));
        let back = read_policy_files(&run).unwrap();
        let owned: Vec<ActingNet> = dec.iter().map(|a| ActingNet::Actor(a.clone())).collect();
        assert_eq!((back.agents, back.team), (owned, None));
        // One centralized actor over joint macro-actions, evaluated (Mac-CAC).
        let cen = actor(10, 64, &mut rng);
        let run = dir.path().join("cac");
        let nets = [SavedNet::team(ActingNetRef::Actor(&cen), true)];
        let written =
            write_policy_files(&run, bp8().into(), layout(), 0.98, run_info(), &nets).unwrap();
        assert_eq!(
            (written.evaluated, written.nets[0].file.as_str()),
            (NetRole::Cen, CEN_FILE)
        );
        let back = read_policy_files(&run).unwrap();
        assert_eq!(
            (back.agents, back.team),
            (vec![], Some(ActingNet::Actor(cen)))
        );
    }

    #[test]
    fn the_evaluated_nets_must_be_marked_and_of_one_role() {
        let dir = tempfile::tempdir().unwrap();
        let (dec, cen) = nets();
        let domain = bp8().build().unwrap();
        let mut nets = saved(NetRole::Dec, &dec, Some(&cen));
        for n in &mut nets {
            n.evaluated = false;
        }
        let write = |nets: &[SavedNet]| {
            let agents = AgentLayout::of_domain(&domain);
            write_policy_files(dir.path(), bp8().into(), agents, 0.98, run_info(), nets)
                .unwrap_err()
                .to_string()
        };
        let err = write(&nets);
        assert!(err.contains("no saved net is marked"), "{err}");
        nets[0].evaluated = true;
        nets[2].evaluated = true;
        let err = write(&nets);
        assert!(err.contains("mixes decentralized and centralized"), "{err}");
        assert!(!dir.path().join(POLICY_DIR).exists());
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
        let nets = saved(NetRole::Dec, &dec, None);
        let err = write_policy_files(dir.path(), bp8().into(), agents, 0.98, run_info(), &nets)
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
