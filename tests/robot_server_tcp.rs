//! The robot server over loopback TCP (moved out of src/deploy/server.rs, issue 11): sessions per
//! connection, limits on line length, connections and idle time, and survival of misbehaving
//! clients.

use macdec::deploy::greedy_action;
use macdec::deploy::policy::mock::{mock_manifest, MockPolicy};
use macdec::deploy::serve::line_reader::MAX_LINE_BYTES;
use macdec::deploy::serve::protocol::Reply;
use macdec::deploy::serve::protocol::{Ack, Request};
use macdec::deploy::serve::robot::RobotSpec;
use macdec::deploy::serve::server::{
    spawn_server, Limits, PolicyFactory, RobotServer, DEFAULT_IDLE_TIMEOUT_SECS,
};
use macdec::deploy::AgentPolicy;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::io::Write;
use std::io::{BufRead, BufReader, Read};
use std::net::{TcpListener, TcpStream};
use std::sync::Arc;
use std::time::Duration;
use std::time::Instant;

const OBS: usize = 5;
const ACTIONS: usize = 8;

fn start_with(limits: Limits, factory: PolicyFactory) -> RobotServer {
    let manifest = mock_manifest(macdec::envs::box_pushing::spec(10, 100));
    let spec = Arc::new(RobotSpec::new(&manifest, 0).unwrap());
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    spawn_server(listener, factory, spec, limits).unwrap()
}

fn start(limits: Limits) -> RobotServer {
    start_with(
        limits,
        Arc::new(|| Box::new(MockPolicy::new(OBS, ACTIONS, 0)) as Box<dyn AgentPolicy>),
    )
}

struct Client {
    stream: TcpStream,
    reader: BufReader<TcpStream>,
}

impl Client {
    fn connect(server: &RobotServer) -> Client {
        let stream = TcpStream::connect(server.local_addr()).unwrap();
        stream.set_nodelay(true).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(20)))
            .unwrap();
        let reader = BufReader::new(stream.try_clone().unwrap());
        Client { stream, reader }
    }

    fn send(&mut self, bytes: &[u8]) {
        (&self.stream).write_all(bytes).unwrap();
    }

    /// The next reply line, or None when the server closed the connection.
    fn next(&mut self) -> Option<Reply> {
        let mut line = String::new();
        let n = self.reader.read_line(&mut line).unwrap();
        (n > 0).then(|| serde_json::from_str(&line).unwrap())
    }

    fn ask(&mut self, line: &str) -> Reply {
        self.send(format!("{line}\n").as_bytes());
        self.next().expect("a reply")
    }
}

/// The reference: the mock policy called directly with the valid messages only.
struct Reference {
    policy: MockPolicy,
    q: Vec<f32>,
}

impl Reference {
    fn new() -> Self {
        Reference {
            policy: MockPolicy::new(OBS, ACTIONS, 0),
            q: vec![0.0; ACTIONS],
        }
    }
    fn observe(&mut self, obs: &[f32]) -> Vec<f32> {
        self.policy.q_values(obs, 0, &mut self.q);
        self.q.clone()
    }
}

fn observe_line(obs: &[f32], done: bool) -> String {
    Request::Observe {
        obs: obs.to_vec(),
        macro_action_done: done,
        step: None,
    }
    .to_line()
}

fn random_obs(rng: &mut ChaCha8Rng) -> Vec<f32> {
    (0..OBS).map(|_| rng.gen_range(0..2) as f32).collect()
}

/// Check a decision against the reference fed the same observation.
fn check_decision(reply: Reply, obs: &[f32], reference: &mut Reference) {
    let want = reference.observe(obs);
    assert_eq!(
        reply,
        Reply::Decision {
            action: greedy_action(&want),
            name: macdec::envs::box_pushing::BoxPushing::new(10, 100)
                .map(|e| e.action_names(0)[greedy_action(&want)].to_string())
                .unwrap(),
            q: want,
        }
    );
}

use macdec::envs::MacroEnv;

/// One fuzzed request line (never containing `\n`) and whether it must be refused.
fn fuzz_line(rng: &mut ChaCha8Rng) -> (Vec<u8>, bool) {
    let valid = |rng: &mut ChaCha8Rng| -> String {
        match rng.gen_range(0..4) {
            0 => r#"{"type":"reset"}"#.to_string(),
            1 => r#"{"type":"info"}"#.to_string(),
            _ => observe_line(&random_obs(rng), rng.gen_bool(0.7)),
        }
    };
    let mut line: Vec<u8>;
    let mut must_fail = true;
    match rng.gen_range(0..10) {
        // Valid messages mutated byte-wise (flip, insert, delete, replace).
        0..=2 => {
            line = valid(rng).into_bytes();
            for _ in 0..rng.gen_range(1..5) {
                let at = rng.gen_range(0..=line.len());
                match rng.gen_range(0..4) {
                    0 if at < line.len() => line[at] ^= 1 << rng.gen_range(0..8),
                    1 => line.insert(at, rng.gen()),
                    2 if at < line.len() => {
                        line.remove(at);
                    }
                    _ if at < line.len() => line[at] = rng.gen(),
                    _ => {}
                }
            }
            must_fail = false; // a mutation may leave a valid message
        }
        // Random bytes, binary garbage included.
        3 => {
            line = (0..rng.gen_range(0..300)).map(|_| rng.gen()).collect();
            must_fail = false;
        }
        // Non-finite or out-of-f32 numbers.
        4 => {
            let bad = [
                "NaN",
                "Infinity",
                "-Infinity",
                "1e39",
                "-4e38",
                "1e400",
                "nan",
            ];
            let mut vals: Vec<String> = (0..OBS).map(|i| (i % 2).to_string()).collect();
            vals[rng.gen_range(0..OBS)] = bad[rng.gen_range(0..bad.len())].to_string();
            line = format!(
                r#"{{"type":"observe","obs":[{}],"macro_action_done":true}}"#,
                vals.join(",")
            )
            .into_bytes();
        }
        // Wrong observation lengths.
        5 => {
            let mut n = rng.gen_range(0..12);
            if n == OBS {
                n += 1;
            }
            line = observe_line(&vec![1.0; n], rng.gen_bool(0.5)).into_bytes();
        }
        // Unknown types and fields, wrong JSON types.
        6 => {
            let cases = [
                r#"{"type":"shutdown"}"#,
                r#"{"type":"observe","obs":[0,0,0,0,0],"macro_action_done":"yes"}"#,
                r#"{"type":"observe","obs":[0,0,0,0,0],"macro_action_done":true,"t":3}"#,
                r#"{"type":null}"#,
                r#"{"type":"observe","obs":{"a":1},"macro_action_done":true}"#,
                r#""observe""#,
                "[]",
                "{}",
            ];
            line = cases[rng.gen_range(0..cases.len())].as_bytes().to_vec();
        }
        // Valid messages.
        _ => {
            line = valid(rng).into_bytes();
            must_fail = false;
        }
    }
    for b in line.iter_mut() {
        if *b == b'\n' {
            *b = b' ';
        }
    }
    (line, must_fail)
}

#[test]
fn fuzzed_input_gets_error_replies_and_never_disturbs_the_hidden_state() {
    let server = start(Limits::default());
    let mut client = Client::connect(&server);
    let mut reference = Reference::new();
    let mut rng = ChaCha8Rng::seed_from_u64(2020);
    let (mut errors, mut decisions) = (0, 0);
    for i in 0..1500 {
        let (line, must_fail) = if i % 97 == 5 {
            // An oversized line of garbage, 64 KiB to 200 KiB.
            let n = MAX_LINE_BYTES + rng.gen_range(1..140_000);
            ((0..n).map(|_| rng.gen_range(b' '..=b'~')).collect(), true)
        } else {
            fuzz_line(&mut rng)
        };
        let mut framed = line.clone();
        framed.push(b'\n');
        client.send(&framed);
        if line.iter().all(u8::is_ascii_whitespace) {
            continue; // blank lines get no reply
        }
        let reply = client.next().expect("the server keeps the connection open");
        match reply {
            Reply::Error { error } => {
                assert!(!error.is_empty());
                if line.len() > MAX_LINE_BYTES {
                    assert!(error.starts_with("line longer than 65536 bytes"), "{error}");
                }
                errors += 1;
            }
            _ if must_fail => panic!("{} was accepted", String::from_utf8_lossy(&line)),
            Reply::Ack { ok: Ack::Reset } => reference.policy.reset(),
            Reply::Ack { ok: Ack::Continue } | Reply::Info { .. } => {}
            decision @ Reply::Decision { .. } => {
                // Accepted, so it is valid JSON: replay its observation on the reference.
                let v: serde_json::Value = serde_json::from_slice(&line).unwrap();
                let obs: Vec<f32> = v["obs"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap() as f32)
                    .collect();
                check_decision(decision, &obs, &mut reference);
                decisions += 1;
            }
        }
        if i % 10 == 0 {
            let obs = random_obs(&mut rng);
            let reply = client.ask(&observe_line(&obs, true));
            check_decision(reply, &obs, &mut reference);
        }
    }
    assert!(
        errors > 500 && decisions > 100,
        "{errors} errors, {decisions} decisions"
    );
    // A fresh connection starts from a zero state while this one carries on.
    let mut other = Client::connect(&server);
    let obs = [1.0, 0.0, 1.0, 0.0, 0.0];
    check_decision(
        other.ask(&observe_line(&obs, true)),
        &obs,
        &mut Reference::new(),
    );
    check_decision(client.ask(&observe_line(&obs, true)), &obs, &mut reference);
}

#[test]
fn connections_keep_separate_hidden_states_under_concurrent_load() {
    let server = start(Limits::default());
    let workers: Vec<_> = (0..4u64)
        .map(|seed| {
            let mut client = Client::connect(&server);
            std::thread::spawn(move || {
                let mut reference = Reference::new();
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                for step in 0..300 {
                    if step % 50 == 49 {
                        assert_eq!(
                            client.ask(r#"{"type":"reset"}"#),
                            Reply::Ack { ok: Ack::Reset }
                        );
                        reference.policy.reset();
                    }
                    let obs = random_obs(&mut rng);
                    if rng.gen_bool(0.3) {
                        let reply = client.ask(&observe_line(&obs, false));
                        assert_eq!(reply, Reply::Ack { ok: Ack::Continue });
                    } else {
                        check_decision(client.ask(&observe_line(&obs, true)), &obs, &mut reference);
                    }
                }
            })
        })
        .collect();
    for w in workers {
        w.join()
            .expect("every connection answers like its own reference");
    }
}

#[test]
fn a_client_leaving_mid_line_is_closed_cleanly_and_others_carry_on() {
    let server = start(Limits::default());
    let mut steady = Client::connect(&server);
    let mut reference = Reference::new();
    let obs = [0.0, 1.0, 1.0, 0.0, 0.0];
    check_decision(steady.ask(&observe_line(&obs, true)), &obs, &mut reference);
    for partial in [
        &b"{\"type\":\"obs"[..],
        b"",
        &vec![b'x'; 3 * MAX_LINE_BYTES],
    ] {
        let mut leaver = Client::connect(&server);
        leaver.send(partial);
        drop(leaver);
        check_decision(steady.ask(&observe_line(&obs, true)), &obs, &mut reference);
    }
    // The leavers' threads end and free their slots.
    let deadline = Instant::now() + Duration::from_secs(10);
    while server.active_connections() > 1 {
        assert!(Instant::now() < deadline, "connections were not released");
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn connections_beyond_the_limit_are_refused_with_a_reason_until_a_slot_frees() {
    let server = start(Limits {
        max_connections: 2,
        ..Limits::default()
    });
    let mut a = Client::connect(&server);
    let mut b = Client::connect(&server);
    assert!(matches!(
        a.ask(r#"{"type":"info"}"#),
        Reply::Info { agent: 0, .. }
    ));
    assert!(matches!(
        b.ask(r#"{"type":"info"}"#),
        Reply::Info { agent: 0, .. }
    ));
    let mut c = Client::connect(&server);
    let Some(Reply::Error { error }) = c.next() else {
        panic!("the third connection must be refused")
    };
    assert!(error.contains("at most 2"), "{error}");
    assert_eq!(c.next(), None, "then closed");
    drop(a);
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let mut d = Client::connect(&server);
        d.send(b"{\"type\":\"reset\"}\n");
        match d.next() {
            Some(Reply::Ack { ok: Ack::Reset }) => break,
            _ => assert!(Instant::now() < deadline, "the freed slot was not reused"),
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(matches!(b.ask(r#"{"type":"info"}"#), Reply::Info { .. }));
}

#[test]
fn a_client_trickling_one_line_byte_by_byte_is_closed_at_the_line_deadline() {
    let server = start(Limits {
        idle_timeout: Some(Duration::from_secs(5)),
        line_timeout: Duration::from_millis(300),
        ..Limits::default()
    });
    let mut slow = TcpStream::connect(server.local_addr()).unwrap();
    let t0 = Instant::now();
    let mut closed = false;
    // One byte every 50 ms, never a newline: each byte resets an idle timer, not the line's.
    for _ in 0..100 {
        if slow.write_all(b" ").is_err() {
            closed = true;
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    if !closed {
        slow.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let mut buf = [0u8; 64];
        closed = matches!(slow.read(&mut buf), Ok(0) | Err(_));
    }
    assert!(closed, "the trickling client kept its connection");
    assert!(t0.elapsed() < Duration::from_secs(10));
}

#[test]
fn limits_have_finite_default_timeouts() {
    let l = Limits::default();
    assert_eq!(
        l.idle_timeout,
        Some(Duration::from_secs(DEFAULT_IDLE_TIMEOUT_SECS))
    );
    assert!(l.line_timeout > Duration::ZERO);
}

#[test]
fn an_idle_connection_is_closed_after_the_idle_timeout() {
    let server = start(Limits {
        idle_timeout: Some(Duration::from_millis(100)),
        ..Limits::default()
    });
    let mut idle = Client::connect(&server);
    assert!(matches!(idle.ask(r#"{"type":"info"}"#), Reply::Info { .. }));
    std::thread::sleep(Duration::from_millis(400));
    assert_eq!(idle.next(), None);
}

#[test]
fn a_panicking_policy_closes_only_its_own_connection() {
    struct Fragile(MockPolicy);
    impl AgentPolicy for Fragile {
        fn obs_len(&self) -> usize {
            OBS
        }
        fn n_actions(&self) -> usize {
            ACTIONS
        }
        fn reset(&mut self) {
            self.0.reset()
        }
        fn q_values(&mut self, obs: &[f32], step: usize, q: &mut [f32]) {
            assert!(obs[0] != 7.0, "deliberate test panic: obs[0] = 7");
            self.0.q_values(obs, step, q)
        }
    }
    let server = start_with(
        Limits::default(),
        Arc::new(|| Box::new(Fragile(MockPolicy::new(OBS, ACTIONS, 0))) as Box<dyn AgentPolicy>),
    );
    let mut steady = Client::connect(&server);
    let mut victim = Client::connect(&server);
    let Reply::Error { error } = victim.ask(&observe_line(&[7.0, 0.0, 0.0, 0.0, 0.0], true)) else {
        panic!("expected an error reply")
    };
    assert!(error.contains("panicked"), "{error}");
    assert_eq!(victim.next(), None);
    let obs = [0.0; OBS];
    check_decision(
        steady.ask(&observe_line(&obs, true)),
        &obs,
        &mut Reference::new(),
    );
}

#[test]
fn shutdown_stops_accepting() {
    let server = start(Limits::default());
    let addr = server.local_addr();
    server.shutdown();
    let refused = TcpStream::connect(addr).map(|s| {
        let mut r = BufReader::new(s);
        let mut line = String::new();
        r.read_line(&mut line).map(|n| n == 0).unwrap_or(true)
    });
    assert!(refused.unwrap_or(true));
}
