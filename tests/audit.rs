//! `macdec audit` on a tiny committed-style results tree: finished runs stored as the repository
//! stores them (config.toml, metrics.csv.gz, finished; no checkpoint, no plain CSV) audit as
//! identical; a tampered value is reported at its row and fails the command.

use std::io::Write;
use std::path::Path;

mod common;

use common::run as macdec;

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    enc.write_all(bytes).unwrap();
    enc.finish().unwrap()
}

/// Turn a run written by `train` into its committed form.
fn commit_style(run: &Path) {
    let csv = std::fs::read(run.join("metrics.csv")).unwrap();
    std::fs::write(run.join("metrics.csv.gz"), gzip(&csv)).unwrap();
    std::fs::remove_file(run.join("metrics.csv")).unwrap();
    std::fs::remove_file(run.join("checkpoint.bin")).unwrap();
}

#[test]
fn committed_runs_audit_identical_and_a_tampered_one_is_caught() {
    let t = tempfile::tempdir().unwrap();
    let tree = t.path().join("reproduction");
    let out = macdec(&[
        "train",
        "--seeds",
        "0..2",
        "--set",
        "total_epi=40",
        "--out",
        tree.to_str().unwrap(),
        "--quiet",
        "--no-plot",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let runs = tree.join("quickstart_bp10/our1");
    for seed in 0..2 {
        commit_style(&runs.join(format!("seed-{seed}")));
    }

    let out = macdec(&["audit", "--results", tree.to_str().unwrap(), "--runs", "5"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        stdout.matches(": identical (5 rows)").count(),
        2,
        "{stdout}"
    );
    assert!(
        stdout.contains("all 2 audited run(s) identical"),
        "{stdout}"
    );

    // Change one return in the fourth row of seed 1.
    let seed1 = runs.join("seed-1");
    let gz = std::fs::read(seed1.join("metrics.csv.gz")).unwrap();
    let mut text = String::new();
    std::io::Read::read_to_string(&mut flate2::read::GzDecoder::new(&gz[..]), &mut text).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut fields: Vec<String> = lines[4].split(',').map(str::to_string).collect();
    let value: f64 = fields[3].parse().unwrap();
    fields[3] = (value + 1.0).to_string();
    lines[4] = fields.join(",");
    let tampered = lines.join("\n") + "\n";
    std::fs::write(seed1.join("metrics.csv.gz"), gzip(tampered.as_bytes())).unwrap();

    let out = macdec(&["audit", "--run", seed1.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!out.status.success(), "{stdout}");
    assert!(stdout.contains("DIFFERS at row 4"), "{stdout}");
    assert!(stdout.contains(&fields[3]), "{stdout}");

    // A directory that is not a finished run cannot be audited, and says why.
    let out = macdec(&["audit", "--run", tree.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!out.status.success());
    assert!(
        stdout.contains("CANNOT AUDIT") && stdout.contains("not a finished run"),
        "{stdout}"
    );
}
