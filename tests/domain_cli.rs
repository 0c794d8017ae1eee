//! `macdec domain` as a process (issue 14): robots started by hand with `macdec robot --listen`
//! are driven by `macdec domain --robots`, which prints exactly `macdec eval`'s episodes; robots
//! given in the wrong order are refused by name.

mod common;

use common::{robot_process, run};

#[test]
fn domain_against_listening_robots_prints_the_eval_and_deploy_episodes() {
    let dir = tempfile::tempdir().unwrap();
    let spec = macdec::envs::warehouse::spec(150, 0.3);
    macdec::deploy::policy::mock::write_mock_policy(dir.path(), spec).unwrap();
    let p = dir.path().to_str().unwrap();
    let robots: Vec<_> = (0..3).map(|i| robot_process(dir.path(), i, true)).collect();
    let addrs: Vec<&str> = robots.iter().map(|r| r.addr.as_str()).collect();
    let common = [
        "--policy",
        p,
        "--episodes",
        "2",
        "--seed",
        "7",
        "--trajectories",
    ];
    let list = addrs.join(",");
    let domain = run(&[&["domain", "--robots", &list][..], &common].concat());
    assert!(
        domain.status.success(),
        "{}",
        String::from_utf8_lossy(&domain.stderr)
    );
    let deploy = run(&[&["deploy", "--mock"][..], &common].concat());
    assert!(deploy.status.success());
    assert_eq!(
        String::from_utf8_lossy(&domain.stdout),
        String::from_utf8_lossy(&deploy.stdout)
    );
    assert_eq!(String::from_utf8_lossy(&domain.stdout).lines().count(), 2);

    let swapped = [addrs[1], addrs[0], addrs[2]].join(",");
    let out = run(&[&["domain", "--robots", &swapped][..], &common].concat());
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("robot of agent 0") && err.contains("serves agent 1"),
        "{err}"
    );
}
