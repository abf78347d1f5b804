//! `FuzzySystem::from_fis` on arbitrary text: never panics; what it accepts round-trips.
#![no_main]

use fuzzy_sugeno::FuzzySystem;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    if let Ok(system) = FuzzySystem::from_fis(text) {
        let read = FuzzySystem::from_fis(&system.to_fis()).expect("a written system reads back");
        assert_eq!(read, system);
    }
});
