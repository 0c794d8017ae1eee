//! The actor-critic methods through the training loop: reproducible from the seed whatever the
//! thread count, a run resumed from a checkpoint continues with exactly the numbers of an
//! uninterrupted one, every method trains on every MacroMARL domain it can and refuses the ones
//! it cannot with a clear error, and the state-critic methods learn Box Pushing 6x6.

use macdec::algos::actor_critic::method::AcMethod;
use macdec::algos::families::AnyLoop;
use macdec::algos::families::{Family, InList, Method};
use macdec::algos::family::FamilyMethod;
use macdec::algos::training_loop::{Advance, EvalPoint};
use macdec::envs::EnvSpec;
use macdec::envs::MacroEnv;
use macdec::experiment::run::train_run::run_rngs;
use macdec::RunConfig;

fn ac_methods() -> impl Iterator<Item = Method> {
    Family::ActorCritic.methods().into_iter()
}

/// The published settings of actor-critic `method` on `spec`.
fn published(spec: &EnvSpec, method: Method) -> macdec::algos::actor_critic::config::AcConfig {
    AcMethod::of(method)
        .expect("an actor-critic method")
        .defaults(spec)
}

/// A short run's config: 4 lanes, 4 episodes per update, an evaluation every 8.
fn short(spec: &EnvSpec, method: Method, episodes: usize) -> RunConfig {
    let mut c = published(spec, method);
    c.total_epi = episodes;
    c.n_env = 4;
    c.train_freq = 4;
    c.c_target_update_freq = 8;
    c.eval_freq = 8;
    c.eval_num_epi = 4;
    c.eps_stable_at = episodes / 2;
    c.n_step_td = 3;
    c.into()
}

fn train(spec: &EnvSpec, config: &RunConfig, method: Method, seed: u64) -> Vec<EvalPoint> {
    let mut l = AnyLoop::new(config, method, seed, run_rngs(seed), || spec.build()).unwrap();
    while l.advance().unwrap() != Advance::Finished {}
    l.evals().to_vec()
}

fn rows(evals: &[EvalPoint]) -> Vec<String> {
    evals
        .iter()
        .map(|e| {
            format!(
                "{} {} {} {:?} {:?} {:?}",
                e.episode,
                e.env_steps,
                e.updates,
                e.eval_return,
                e.eval_return_undiscounted,
                e.family
            )
        })
        .collect()
}

#[test]
fn same_seed_same_numbers_whatever_the_threads_and_across_a_resume() {
    let spec = macdec::envs::bp_ma_v0::spec(4, 20);
    for method in ac_methods() {
        let config = short(&spec, method, 48);
        let whole = rows(&train(&spec, &config, method, 3));
        assert_eq!(whole.len(), 6, "{method}: evaluations at 0, 8, ..., 40");
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap()
            .install(|| rows(&train(&spec, &config, method, 3)));
        assert_eq!(whole, two, "{method}: thread count changed the numbers");
        assert_ne!(
            whole,
            rows(&train(&spec, &config, method, 4)),
            "{method}: seeds differ"
        );
        // Stop after 20 episodes, save and restore the whole loop, finish.
        let mut l = AnyLoop::new(&config, method, 3, run_rngs(3), || spec.build()).unwrap();
        while l.episodes() < 20 {
            l.advance().unwrap();
        }
        let bytes = bincode::serialize(&l).unwrap();
        drop(l);
        let mut back: AnyLoop = bincode::deserialize(&bytes).unwrap();
        while back.advance().unwrap() != Advance::Finished {}
        assert_eq!(whole, rows(back.evals()), "{method}: a resumed run differs");
    }
}

#[test]
fn every_method_trains_on_every_macromarl_domain_that_gives_what_it_needs() {
    let domains = [
        ("BP-MA-v0", toml::toml! { grid_dim = [6, 6] }),
        ("OSD-D-v7", toml::Table::new()),
        ("OSD-T-v0", toml::Table::new()),
        ("OSD-T-v1", toml::Table::new()),
        ("OSD-F-v0", toml::Table::new()),
        ("Overcooked-MA-v1", toml::Table::new()),
        ("BP_MA", toml::toml! { grid_dim = 8 }),
        ("OSD_S_4", toml::Table::new()),
    ];
    for (id, keys) in domains {
        let spec = EnvSpec::new(id, &keys).unwrap();
        let has_state = spec.build().unwrap().state_size() > 0;
        for method in ac_methods() {
            let config = short(&spec, method, 8);
            let needs_state = matches!(
                method,
                Method::ActorCritic(AcMethod::NaiveMacIasc)
                    | Method::ActorCritic(AcMethod::MacIaisc)
            );
            let built = AnyLoop::new(&config, method, 0, run_rngs(0), || spec.build());
            match built {
                Ok(mut l) if !needs_state || has_state => {
                    while l.advance().unwrap() != Advance::Finished {}
                    assert_eq!(l.updates(), 2, "{method} on {id}");
                    assert!(l.evals()[0].eval_return.is_finite(), "{method} on {id}");
                }
                Ok(_) => panic!("{method} on {id}: trained without a state"),
                Err(e) => {
                    assert!(needs_state && !has_state, "{method} on {id}: {e}");
                    assert!(e.to_string().contains("get_state()"), "{e}");
                }
            }
        }
    }
}

#[test]
fn the_state_critic_methods_learn_box_pushing_6x6() {
    // The published settings, 12 000 episodes, seed 0: the state-critic methods push the big box
    // (optimum 270.61 at gamma 0.98; the two small boxes alone give at most 37.26).
    let spec = macdec::envs::bp_ma_v0::spec(6, 100);
    for method in [
        Method::ActorCritic(AcMethod::NaiveMacIasc),
        Method::ActorCritic(AcMethod::MacIaisc),
    ] {
        let mut c = published(&spec, method);
        c.total_epi = 12_000;
        let evals = train(&spec, &c.into(), method, 0);
        let best = evals.iter().map(|e| e.eval_return).fold(f64::MIN, f64::max);
        assert!(best > 150.0, "{method}: best sampled evaluation {best}");
    }
}
