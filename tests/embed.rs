//! The `embed` example (the shortest honest integration, written only from
//! the crate root's front) runs and passes its own checks: unbiased
//! estimates, lights behind the wall unlearned, less error than uniform.

#[path = "../examples/embed.rs"]
#[allow(dead_code)]
mod embed;

#[test]
fn embed_runs_and_its_checks_hold() {
    assert!(embed::run());
}
