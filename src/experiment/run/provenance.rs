//! Where a run's numbers came from: the macdec version and git commit that trained it, the
//! arithmetic path and the CPU. Recorded in each run's `config.toml` so a committed result can be
//! audited against the code that made it, and so figures can say when they mix builds.

use serde::{Deserialize, Serialize};

/// The build and machine a run was trained on. Not part of a run's identity: resuming on
/// another commit or CPU is allowed (and `macdec plot` reports mixtures).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Provenance {
    /// The crate version (`CARGO_PKG_VERSION`).
    pub macdec_version: String,
    /// The commit hash, `<hash>-dirty` if the code differed from it, or `unknown`.
    pub git_commit: String,
    /// `avx512`, `avx2-fma` or `portable-fma`, or, from builds before 2026-12-04, `avx2` or
    /// `portable` (see [`crate::autograd::kernels::kernel_path`]).
    pub kernel_path: String,
    /// The CPU's model name with its family (see [`cpu_model`]), or `unknown`.
    pub cpu_model: String,
}

impl Provenance {
    /// The provenance of this process on this machine.
    pub fn current() -> Self {
        Provenance {
            macdec_version: env!("CARGO_PKG_VERSION").to_string(),
            git_commit: env!("MACDEC_GIT_COMMIT").to_string(),
            kernel_path: crate::autograd::kernels::kernel_path().to_string(),
            cpu_model: cpu_model(),
        }
    }
}

/// The CPU's model name with its family (family 25 is Zen 4, 26 is Zen 5), or `unknown`.
pub fn cpu_model() -> String {
    let Ok(text) = std::fs::read_to_string("/proc/cpuinfo") else {
        return "unknown".to_string();
    };
    let field = |key: &str| {
        text.lines()
            .find(|l| l.split(':').next().is_some_and(|k| k.trim() == key))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
    };
    match (field("model name"), field("cpu family")) {
        (Some(name), Some(family)) => format!("{name} (family {family})"),
        (Some(name), None) => name,
        _ => "unknown".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn current_provenance_names_this_build() {
        let p = Provenance::current();
        assert_eq!(p.macdec_version, env!("CARGO_PKG_VERSION"));
        assert!(p.git_commit == "unknown" || p.git_commit.len() >= 40);
        assert!(["avx512", "avx2-fma", "portable-fma"].contains(&p.kernel_path.as_str()));
        assert!(!p.cpu_model.is_empty());
    }
}
