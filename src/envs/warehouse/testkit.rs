//! Test helpers: the spec harness's `queues` mode (`docs/WAREHOUSE.md` §14 conventions), a recorded
//! trajectory, observation strings, and the spec's simple closed-loop policy.

use rand::SeedableRng;

use super::{Fetch, Human, Turtlebot, Warehouse};
use crate::envs::{EnvRng, MacroEnv};

/// What one step produced, plus a state snapshot after it.
#[derive(Debug, Clone)]
pub struct Rec {
    pub t: usize,
    pub executed: [usize; 3],
    pub obs: [Vec<f32>; 3],
    pub reward: f64,
    pub done: bool,
    pub mac_done: [bool; 3],
    pub tbs: [Turtlebot; 2],
    pub fetch: Fetch,
    pub human: Human,
}

/// A value no agent accepts, passed for busy agents to prove it is ignored (the training code
/// passes -1).
pub const BUSY: usize = usize::MAX;

/// Parse `"0001 0000 000 00"` into floats (spaces ignored).
pub fn o(s: &str) -> Vec<f32> {
    s.chars()
        .filter(|c| !c.is_whitespace())
        .map(|c| c.to_digit(10).expect("digit") as f32)
        .collect()
}

fn snapshot(env: &Warehouse, reward: f64, done: bool) -> Rec {
    let m = env.mac_done();
    let e = env.executed();
    Rec {
        t: env.t(),
        executed: [e[0], e[1], e[2]],
        obs: [0, 1, 2].map(|i| env.obs(i).to_vec()),
        reward,
        done,
        mac_done: [m[0], m[1], m[2]],
        tbs: [env.turtlebot(0).clone(), env.turtlebot(1).clone()],
        fetch: env.fetch().clone(),
        human: env.human().clone(),
    }
}

/// Run `policy` (called for each step with the env, returning the joint action) until done or
/// `max_steps`. Element 0 of the result is the reset state (t = 0).
pub fn run_policy(
    env: &mut Warehouse,
    max_steps: usize,
    mut policy: impl FnMut(&Warehouse) -> [usize; 3],
) -> Vec<Rec> {
    let mut rng = EnvRng::seed_from_u64(0);
    env.reset(&mut rng);
    let mut recs = vec![snapshot(env, 0.0, false)];
    for _ in 0..max_steps {
        let a = policy(env);
        let out = env.step(&a, &mut rng).expect("valid step");
        recs.push(snapshot(env, out.reward, out.done));
        if out.done {
            break;
        }
    }
    recs
}

/// The harness's queues mode: a free agent takes its queue's next entry, or its default once the
/// queue is empty; a busy agent is passed [`BUSY`].
pub fn run_queues(queues: [&[usize]; 3], defaults: [usize; 3], max_steps: usize) -> Vec<Rec> {
    let mut env = Warehouse::paper(150).expect("paper params");
    let mut next = [0usize; 3];
    run_policy(&mut env, max_steps, |env| {
        let mut a = [BUSY; 3];
        for i in 0..3 {
            if env.is_free(i) {
                a[i] = queues[i].get(next[i]).copied().unwrap_or(defaults[i]);
                next[i] += 1;
            }
        }
        a
    })
}

/// The spec's simple closed-loop decentralized policy (section 14, after S13). Each agent reads
/// only its own observation; the Fetch counts the searches it issued. `search_first` swaps the
/// Fetch's priorities ("search before pass").
pub struct SimplePolicy {
    pub searches: usize,
    pub search_first: bool,
}

impl SimplePolicy {
    pub fn act(&mut self, env: &Warehouse) -> [usize; 3] {
        let mut a = [BUSY; 3];
        for (i, slot) in a.iter_mut().enumerate().take(2) {
            if env.is_free(i) {
                let basket: f32 = env.obs(i)[8..11].iter().sum();
                *slot = if basket > 0.0 { 0 } else { 2 };
            }
        }
        if env.is_free(2) {
            let f = env.obs(2);
            let s = f[0] + 2.0 * f[1];
            let pass = if s > 0.0 && f[2] == 1.0 {
                Some(1)
            } else if s > 0.0 && f[3] == 1.0 {
                Some(2)
            } else {
                None
            };
            let search = (s < 2.0 && self.searches < 3).then_some(3 + self.searches);
            let choice = if self.search_first {
                search.or(pass)
            } else {
                pass.or(search)
            };
            if choice.is_some_and(|c| c >= 3) {
                self.searches += 1;
            }
            a[2] = choice.unwrap_or(0);
        }
        a
    }
}
