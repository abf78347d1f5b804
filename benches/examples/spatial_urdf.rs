//! Writes what `benches/pinocchio/spatial.cpp` needs to time Pinocchio on the spatial arms of
//! the speed comparison (`hrm_benches::spatial_arm`, 10 and 100 links) into a folder
//! (`benches/pinocchio/run.sh build` runs this): `spatial_<n>.urdf`, the arm's URDF export, and
//! `spatial_<n>.txt`, its modal map and the benches' state, so that the harness reduces the same
//! way and checks its answer against hrm's:
//!
//! ```text
//! <joints 2n> <coordinates m>
//! 2n lines of m values: J, row by row (theta = J a)
//! a, a_dot, tau*, and hrm's a_ddot: one line of m values each
//! ```
//!
//! ```sh
//! cargo run -p hrm-benches --example spatial_urdf -- /tmp/spatial
//! ```

use modal_reduce::spatial::{SpatialReducedData, spatial_forward_dynamics};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Some(folder) = std::env::args_os().nth(1).map(PathBuf::from) else {
        return Err("usage: spatial_urdf <folder>".into());
    };
    std::fs::create_dir_all(&folder)?;
    for n in [10, 100] {
        let model = hrm_benches::spatial_arm(n);
        let robot = robot_desc::from_spatial_arm(&model, "spatial_arm")?;
        std::fs::write(
            folder.join(format!("spatial_{n}.urdf")),
            robot_desc::write_urdf(&robot)?,
        )?;
        let [a, a_dot, tau_star] = hrm_benches::spatial_state();
        let m = model.n_coords();
        let mut a_ddot = vec![0.0; m];
        let mut data = SpatialReducedData::new(&model);
        spatial_forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut a_ddot)?;
        let map = model.map();
        let line = |values: &[f64]| {
            let texts: Vec<String> = values.iter().map(|x| format!("{x:e}")).collect();
            texts.join(" ") + "\n"
        };
        let mut text = format!("{} {m}\n", map.n_joints());
        for j in 0..map.n_joints() {
            text += &line(map.row(j));
        }
        for values in [&a, &a_dot, &tau_star, &a_ddot] {
            text += &line(values);
        }
        let path = folder.join(format!("spatial_{n}.txt"));
        std::fs::write(&path, text)?;
        println!("{}", path.display());
    }
    Ok(())
}
