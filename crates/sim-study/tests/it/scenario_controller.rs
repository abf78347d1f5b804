//! `Scenario::build_with_controller`: a scenario closed by a controller written elsewhere (the
//! Python package's callables) runs the scenario's loop exactly as `build` does.

use sim_core::SimError;
use sim_core::controller::{ControlContext, Controller, ControllerError, FuzzyController};
use sim_study::Scenario;

fn short_tracking() -> Scenario {
    let mut scenario = Scenario::builtin("paper-tracking").unwrap();
    scenario.duration = 0.2;
    scenario
}

#[test]
fn the_same_controller_given_from_outside_gives_the_same_run() {
    let scenario = short_tracking();
    let builtin = scenario.build().unwrap().run().unwrap();
    let fuzzy = FuzzyController::new(fuzzy_sugeno::paper_controller(), 2).unwrap();
    let outside = scenario
        .build_with_controller(Box::new(fuzzy))
        .unwrap()
        .run()
        .unwrap();
    assert_eq!(outside, builtin);
}

/// Counts its samples and returns zero torque.
struct Counter {
    calls: std::sync::Arc<std::sync::atomic::AtomicUsize>,
    m: usize,
}

impl Controller for Counter {
    fn control(&mut self, _: &ControlContext<'_>, tau: &mut [f64]) -> Result<(), ControllerError> {
        self.calls
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        tau.fill(0.0);
        Ok(())
    }

    fn n_coords(&self) -> Option<usize> {
        Some(self.m)
    }
}

#[test]
fn the_scenarios_period_samples_it_and_sizes_are_checked() {
    let mut scenario = short_tracking();
    scenario.controller.period = Some(1e-3);
    scenario.limits.max_modal_error = 100.0;
    // The `[controller]` keys other than the period are not used: gains of the wrong length
    // would refuse the built-in controllers, not this one.
    scenario.controller.kp = Some(vec![1.0; 5]);
    let calls = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let counter = Counter {
        calls: calls.clone(),
        m: 2,
    };
    let run = scenario
        .build_with_controller(Box::new(counter))
        .unwrap()
        .run()
        .unwrap();
    assert_eq!(run.summary.controller_samples, 201);
    assert_eq!(calls.load(std::sync::atomic::Ordering::Relaxed), 201);
    let wrong = Counter { calls, m: 3 };
    let Err(SimError::InvalidSetting { name, requirement }) =
        scenario.build_with_controller(Box::new(wrong))
    else {
        panic!("a controller of 3 coordinates on a family of 2 must be refused");
    };
    assert_eq!(name, "controller");
    assert!(requirement.contains("3 coordinates"), "{requirement}");
    // The scenario's own settings are checked as by `build`.
    scenario.duration = -1.0;
    let counter = Counter {
        calls: Default::default(),
        m: 2,
    };
    let error = scenario
        .build_with_controller(Box::new(counter))
        .err()
        .unwrap();
    assert!(
        error.to_string().contains("duration must be positive"),
        "{error}"
    );
}
