//! Takagi-Sugeno fuzzy inference (section 4 of the paper).
#![deny(missing_docs)]
