//! `Scenario::from_toml` and `build` on arbitrary text: never panic; what parses writes back.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sim_study::Scenario;

fuzz_target!(|text: &str| {
    if let Ok(scenario) = Scenario::from_toml(text) {
        let read = Scenario::from_toml(&scenario.to_toml()).expect("a written scenario reads back");
        if scenario.clone() == scenario {
            assert_eq!(read, scenario);
        }
        let _ = scenario.build();
    }
});
