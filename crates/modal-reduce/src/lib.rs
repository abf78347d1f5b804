//! Projection of planar chain dynamics onto constant modal coordinates (eqs 13-18 of the paper):
//! `M* = J^T M J`, `C* = J^T C`, `G* = J^T G`, `tau* = J^T tau`.
#![deny(missing_docs)]
