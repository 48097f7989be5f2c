//! Records the git commit grainlab is built from (`GRAINLAB_COMMIT`, for a run's
//! provenance): `git rev-parse HEAD`, with `+modified` when tracked files differ from it,
//! or `unknown` outside a git checkout or without git.

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status.success().then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let commit = match git(&["rev-parse", "HEAD"]) {
        Some(c) if !c.is_empty() => {
            let modified = git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
            format!("{c}{}", if modified { "+modified" } else { "" })
        }
        _ => "unknown".into(),
    };
    println!("cargo:rustc-env=GRAINLAB_COMMIT={commit}");
    // Again when the commit or the tracked files change.
    for path in [".git/HEAD", ".git/index", ".git/refs", "src", "Cargo.toml", "docs/effect-costs.json"] {
        println!("cargo:rerun-if-changed={path}");
    }
}
