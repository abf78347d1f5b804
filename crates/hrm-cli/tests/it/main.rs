//! The integration tests of the `hrm` command, one binary, each running the built executable:
//! `arm_cmd` for `hrm arm check` and `hrm arm export`,
//! `cli_errors` and `cli_fuzz` for bad command lines and files, `eval_stream` and
//! `eval_derivatives` and `eval_robot` for `hrm eval`, `fis_export`, `fis_imitate` and `fis_train` for `hrm fis`, `simulate_links` for the points `hrm simulate` writes, `simulate_spatial` for `hrm simulate` and `hrm view` on a spatial arm, and `common` for
//! running `hrm` in a scratch folder.

mod arm_cmd;
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
mod simulate_spatial;
