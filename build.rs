//! Records the git commit the binary is built from, so every run can say what trained it.
//!
//! `MACDEC_GIT_COMMIT` is the commit hash, with `-dirty` when tracked code (src/, Cargo.*,
//! build.rs) differs from it, or `unknown` outside a git checkout.

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    // Git's own paths: in a linked worktree `.git` is a file and HEAD and the index live
    // elsewhere; watching a path that does not exist would rebuild the crate every time.
    for name in ["HEAD", "index"] {
        let path =
            git(&["rev-parse", "--git-path", name]).unwrap_or_else(|| format!(".git/{name}"));
        println!("cargo:rerun-if-changed={path}");
    }
    for path in ["src", "Cargo.toml", "Cargo.lock", "build.rs"] {
        println!("cargo:rerun-if-changed={path}");
    }
    let commit = match git(&["rev-parse", "HEAD"]) {
        Some(hash) if !hash.is_empty() => {
            // --no-optional-locks: a plain `git status` refreshes and rewrites .git/index (on a
            // fresh clone, always), which this script watches, so the next build would rerun it
            // and recompile the crate for nothing.
            let dirty = git(&[
                "--no-optional-locks",
                "status",
                "--porcelain",
                "--untracked-files=no",
                "--",
                "src",
                "Cargo.toml",
                "Cargo.lock",
                "build.rs",
            ])
            .is_none_or(|s| !s.is_empty());
            if dirty {
                format!("{hash}-dirty")
            } else {
                hash
            }
        }
        _ => "unknown".to_string(),
    };
    println!("cargo:rustc-env=MACDEC_GIT_COMMIT={commit}");
}
