//! The integration tests of the `hrm` command, one binary, each running the built executable:
//! `cli_errors` and `cli_fuzz` for bad command lines and files, `eval_stream` and
//! `eval_derivatives` and `eval_robot` for `hrm eval`, `fis_export`, `fis_imitate` and `fis_train` for `hrm fis`, `simulate_links` for the points `hrm simulate` writes, and `common` for
//! running `hrm` in a scratch folder.

mod cli_errors;
mod cli_fuzz;
mod common;
mod eval_derivatives;
mod eval_robot;
mod eval_stream;
mod fis_export;
mod fis_imitate;
mod fis_train;
mod simulate_links;
