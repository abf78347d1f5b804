//! Closed-loop simulation of modal-coordinate controllers on hyper-redundant manipulators
//! (section 5 of the paper).
#![deny(missing_docs)]
