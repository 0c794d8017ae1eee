//! `macdec import --reference acac`: a policy directory from ACAC's trained actors. ACAC saves
//! each agent's actor as `<run_id>_agent_<i>_1.tar` (`ckpt_utils.py: save_checkpoint_cent`,
//! key `actor_net_state_dict`); `scripts/torch_to_safetensors.py --key actor_net_state_dict`
//! converts one to safetensors. Each file must be exactly an `AgentCentricGRUActor`'s tensors
//! under ACAC's names (`encoder.fc1.*` ... `fc4.*`, `ln.*` when `use_actor_ln`,
//! `time_embedding.weight` when `time_emb_actor`), F32 and finite, with the domain agent's
//! observation and macro-action counts and the same architecture as agent 0's. The policy keeps
//! the time table the file holds, so it acts exactly as ACAC's actor did.

use super::import::{
    check_finite, imported_run, read_bounded, request_domain, ImportError, ImportRequest,
    ImportedFile, MAX_STATE_DICT_BYTES,
};
use crate::envs::MacroEnv;
use crate::nn::safetensors_io::named_to_safetensors_bytes;
use crate::nn::{StateDict, TimedAcacActor, MAX_NET_WIDTH};
use crate::policy_files::architecture::Architecture;
use crate::policy_files::Manifest;
use std::path::{Path, PathBuf};

/// Check one agent's ACAC actor file `bytes` (from `path`) against a domain agent with
/// `obs_len` observation values and `n_actions` macro-actions.
pub fn check_acac_actor(
    bytes: &[u8],
    path: &Path,
    obs_len: usize,
    n_actions: usize,
) -> Result<TimedAcacActor, ImportError> {
    let unreadable = |reason: String| ImportError::Unreadable {
        path: path.to_path_buf(),
        reason,
    };
    let sd = StateDict::parse(bytes, path).map_err(|e| unreadable(e.to_string()))?;
    let net = TimedAcacActor::from_state_dict(&sd).map_err(|e| unreadable(e.to_string()))?;
    let a = &net.actor;
    let widths = [
        a.encoder.fc1.output(),
        a.fc3.output(),
        a.encoder.gru.hidden(),
    ];
    if widths.iter().any(|&w| w == 0 || w > MAX_NET_WIDTH) {
        return Err(unreadable(format!(
            "widths [{}, {}] and hidden size {} must be in 1..={MAX_NET_WIDTH}",
            widths[0], widths[1], widths[2]
        )));
    }
    let shape =
        |name: &str, found: Vec<usize>, expected: String, hint: String| ImportError::Shape {
            path: path.to_path_buf(),
            name: name.to_string(),
            found,
            expected,
            hint,
        };
    if net.obs_len() != obs_len {
        let dim = net.time.as_ref().map_or(0, |t| t.dim());
        let table = if dim == 0 {
            String::new()
        } else {
            format!(", and the file's time table adds {dim}")
        };
        return Err(shape(
            "encoder.fc1.weight",
            vec![widths[0], a.input()],
            format!("[{}, {}]", widths[0], obs_len + dim),
            format!(" (this agent of the domain has {obs_len} observation values{table})"),
        ));
    }
    if net.n_actions() != n_actions {
        return Err(shape(
            "fc4.weight",
            vec![net.n_actions(), widths[1]],
            format!("[{n_actions}, {}]", widths[1]),
            format!(" (this agent of the domain has {n_actions} macro-actions)"),
        ));
    }
    check_finite(path, &net.named())?;
    Ok(net)
}

/// Import one ACAC actor file per agent into the policy directory `out` (see the module doc).
pub fn import_acac_actors(request: &ImportRequest, out: &Path) -> Result<Manifest, ImportError> {
    let env = request_domain(request)?;
    let mut weights = Vec::with_capacity(request.agents.len());
    let mut sources = Vec::with_capacity(request.agents.len());
    let mut first: Option<(PathBuf, Architecture)> = None;
    for (agent, path) in request.agents.iter().enumerate() {
        let bytes = read_bounded(path, MAX_STATE_DICT_BYTES)?;
        let net = check_acac_actor(&bytes, path, env.obs_sizes()[agent], env.n_actions()[agent])?;
        let arch = Architecture::acac_actor(&net);
        match &first {
            Some((first_path, first_arch)) if *first_arch != arch => {
                return Err(ImportError::AcacActorMismatch {
                    path: path.clone(),
                    arch: describe(&arch),
                    first: first_path.clone(),
                    first_arch: describe(first_arch),
                })
            }
            Some(_) => {}
            None => first = Some((path.clone(), arch)),
        }
        sources.push(ImportedFile::new(agent, path, &bytes));
        weights.push(named_to_safetensors_bytes(&net.named()));
    }
    let (_, arch) = first.expect("a domain has at least one agent");
    let run = imported_run(serde_json::json!({
        "imported_from": "ACAC actor state_dicts (reference code, actor_net_state_dict)",
        "files": sources,
    }));
    Ok(Manifest::write_policy(
        out,
        request.env.clone(),
        request.discount,
        arch,
        run,
        &weights,
    )?)
}

/// An ACAC actor's architecture in words, for the mismatch message.
fn describe(a: &Architecture) -> String {
    format!(
        "widths [{}, {}], hidden size {}, LayerNorm {}, time table {}",
        a.mlp_layer_size,
        a.mlp_out_size.unwrap_or(a.mlp_layer_size),
        a.rnn_h_size,
        if a.layer_norm == Some(true) {
            "yes"
        } else {
            "no"
        },
        a.time_embedding
            .map_or("none".to_string(), |[r, d]| format!("{r} x {d}"))
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::{AcacActor, TimeEmbedding};
    use rand::SeedableRng;

    fn actor_bytes(
        obs: usize,
        actions: usize,
        hidden: usize,
        edit: impl Fn(&mut TimedAcacActor),
    ) -> Vec<u8> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let mut net = TimedAcacActor {
            actor: AcacActor::new(obs + 4, [8, 6], hidden, actions, true, &mut rng),
            time: Some(TimeEmbedding::sinusoidal(30, 4).unwrap()),
        };
        edit(&mut net);
        named_to_safetensors_bytes(&net.named())
    }

    #[test]
    fn wrong_sizes_unknown_tensors_and_non_finite_weights_are_named() {
        let p = Path::new("a0.safetensors");
        let ok = actor_bytes(5, 8, 4, |_| {});
        assert_eq!(check_acac_actor(&ok, p, 5, 8).unwrap().obs_len(), 5);
        let err = check_acac_actor(&ok, p, 6, 8).unwrap_err().to_string();
        assert!(
            err.contains("encoder.fc1.weight") && err.contains("6 observation values"),
            "{err}"
        );
        let err = check_acac_actor(&ok, p, 5, 7).unwrap_err().to_string();
        assert!(
            err.contains("fc4.weight") && err.contains("7 macro-actions"),
            "{err}"
        );
        let bad = actor_bytes(5, 8, 4, |n| n.actor.fc3.bias[1] = f32::NAN);
        let err = check_acac_actor(&bad, p, 5, 8).unwrap_err().to_string();
        assert!(err.contains("fc3.bias") && err.contains("NaN"), "{err}");
        let err = check_acac_actor(b"junk", p, 5, 8).unwrap_err().to_string();
        assert!(err.contains("not a safetensors file"), "{err}");
    }
}
