//! `macdec import --reference macromarl`: a policy directory from MacroMARL's trained actors
//! (`visualization/policy_nns/*/agent_state_dict*.pt`, converted by
//! `scripts/torch_to_safetensors.py`), one `Actor.state_dict()` per agent (`docs/MACROMARL.md`
//! 2.4, 4). Each file must be exactly the actor's twelve tensors, F32 and finite, with its input
//! and output sizes the domain agent's and the same widths as agent 0's; the directory is written
//! by [`Manifest::write_policy`] as for any other policy, its nets of kind `actor`.

use super::import::{
    check_finite, imported_run, read_bounded, request_domain, ImportError, ImportRequest,
    ImportedFile, MAX_STATE_DICT_BYTES,
};
use crate::envs::MacroEnv;
use crate::nn::{GruActor, GruActorConfig};
use crate::policy_files::architecture::Architecture;
use crate::policy_files::Manifest;
use std::path::Path;

/// Check one agent's actor file `bytes` (from `path`) against a domain agent with `obs_len`
/// observation values and `n_actions` macro-actions. Returns the actor's sizes.
pub fn check_actor(
    bytes: &[u8],
    path: &Path,
    obs_len: usize,
    n_actions: usize,
) -> Result<GruActorConfig, ImportError> {
    let actor =
        GruActor::from_safetensors_bytes(bytes, path).map_err(|e| ImportError::Unreadable {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
    let cfg = actor.config();
    for (name, got, want, what) in [
        ("fc1.weight", cfg.input, obs_len, "observation values"),
        ("fc4.weight", cfg.output, n_actions, "macro-actions"),
    ] {
        if got != want {
            return Err(ImportError::Shape {
                path: path.to_path_buf(),
                name: name.to_string(),
                found: if name == "fc1.weight" {
                    vec![cfg.mlp[0], got]
                } else {
                    vec![got, cfg.mlp[1]]
                },
                expected: if name == "fc1.weight" {
                    format!("[{}, {want}]", cfg.mlp[0])
                } else {
                    format!("[{want}, {}]", cfg.mlp[1])
                },
                hint: format!(" (this agent of the domain has {want} {what})"),
            });
        }
    }
    let widest = cfg.mlp[0].max(cfg.mlp[1]).max(cfg.hidden);
    if widest == 0 || widest > crate::nn::MAX_NET_WIDTH {
        return Err(ImportError::Unreadable {
            path: path.to_path_buf(),
            reason: format!(
                "layer widths {:?} and hidden size {} must be in 1..={}",
                cfg.mlp,
                cfg.hidden,
                crate::nn::MAX_NET_WIDTH
            ),
        });
    }
    check_finite(path, &actor.named())?;
    Ok(cfg)
}

/// Import one actor file per agent into the policy directory `out` (see the module doc).
pub fn import_actors(request: &ImportRequest, out: &Path) -> Result<Manifest, ImportError> {
    let env = request_domain(request)?;
    let mut weights = Vec::with_capacity(request.agents.len());
    let mut sources = Vec::with_capacity(request.agents.len());
    let mut first: Option<GruActorConfig> = None;
    for (agent, path) in request.agents.iter().enumerate() {
        let bytes = read_bounded(path, MAX_STATE_DICT_BYTES)?;
        let cfg = check_actor(&bytes, path, env.obs_sizes()[agent], env.n_actions()[agent])?;
        if let Some(f) = first {
            if (f.mlp, f.hidden) != (cfg.mlp, cfg.hidden) {
                return Err(ImportError::ActorMismatch {
                    path: path.clone(),
                    mlp: cfg.mlp,
                    hidden: cfg.hidden,
                    first: request.agents[0].clone(),
                    first_mlp: f.mlp,
                    first_hidden: f.hidden,
                });
            }
        }
        first.get_or_insert(cfg);
        sources.push(ImportedFile::new(agent, path, &bytes));
        weights.push(bytes);
    }
    let cfg = first.expect("a domain has at least one agent");
    let run = imported_run(serde_json::json!({
        "imported_from": "MacroMARL actor state_dicts (reference code)",
        "files": sources,
    }));
    Ok(Manifest::write_policy(
        out,
        request.env.clone(),
        request.discount,
        Architecture::gru_actor(cfg.mlp, cfg.hidden),
        run,
        &weights,
    )?)
}
