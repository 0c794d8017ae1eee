//! Every evaluation records the undiscounted return beside the discounted one: with a discount
//! of 1 the two are the same number, below 1 they differ, for both families.

use macdec::algos::actor_critic::method::AcMethod;
use macdec::algos::families::AnyLoop;
use macdec::algos::families::Method;
use macdec::algos::family::FamilyMethod;
use macdec::algos::training_loop::{Advance, EvalPoint};
use macdec::algos::value::method::ValueMethod;
use macdec::envs::EnvSpec;
use macdec::experiment::run::train_run::run_rngs;
use macdec::RunConfig;

fn train(spec: &EnvSpec, config: &RunConfig, method: Method) -> Vec<EvalPoint> {
    let mut l = AnyLoop::new(config, method, 2, run_rngs(2), || spec.build()).unwrap();
    while l.advance().unwrap() != Advance::Finished {}
    l.evals().to_vec()
}

/// Whether every evaluation's two returns are the same number, after checking both are there.
fn same(evals: &[EvalPoint]) -> bool {
    assert!(evals.len() >= 3);
    evals.iter().all(|e| {
        let plain = e.eval_return_undiscounted.expect("recorded");
        assert!(plain.is_finite() && e.eval_return.is_finite());
        plain.to_bits() == e.eval_return.to_bits()
    })
}

#[test]
fn value_methods_record_the_undiscounted_return() {
    let spec = macdec::envs::box_pushing::spec(10, 100);
    for (discount, equal) in [(1.0, true), (0.9, false)] {
        let mut c = ValueMethod::DecHddrqn.defaults(&spec);
        c.total_epi = 20;
        c.eval_freq = 5;
        c.discount = discount;
        let evals = train(&spec, &c.into(), Method::Value(ValueMethod::DecHddrqn));
        assert_eq!(same(&evals), equal, "discount {discount}: {evals:?}");
    }
}

#[test]
fn actor_critic_methods_record_the_undiscounted_return() {
    let spec = macdec::envs::bp_ma_v0::spec(4, 20);
    for (gamma, equal) in [(1.0, true), (0.9, false)] {
        let mut c = AcMethod::MacIac.defaults(&spec);
        c.total_epi = 24;
        c.n_env = 4;
        c.train_freq = 4;
        c.eval_freq = 8;
        c.eval_num_epi = 4;
        c.gamma = gamma;
        let evals = train(&spec, &c.into(), Method::ActorCritic(AcMethod::MacIac));
        assert_eq!(same(&evals), equal, "gamma {gamma}: {evals:?}");
    }
}
