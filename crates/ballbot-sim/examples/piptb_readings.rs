//! The PIPTB controller comparison with the paper's settings (3 trials per controller), read
//! both ways: `t3` fixed at `t2 + 1.4 s` and `t3` when the testbed stopped, with the stop
//! criterion's sensitivity (what `ballbot reproduce` prints for these parts, without the
//! other studies).
//!
//! ```text
//! cargo run --release -p ballbot-sim --example piptb_readings
//! ```

use ballbot_sim::planar::ControllerKind;
use ballbot_sim::report::piptb::{
    SENSITIVITY_BANDS_M_PER_S, SENSITIVITY_HOLDS_SECS, readings_table, stop_sensitivity_table,
};
use ballbot_sim::studies::piptb::{self, PiptbSettings};
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let settings = PiptbSettings::paper();
    let brake = piptb::braking_reference(&settings)?;
    let fixed = piptb::run(&settings, brake, &ControllerKind::ALL, None, &mut |_, _| {})?;
    let until = fixed.until_stopped(&settings.stop_criterion())?;
    println!("{}", fixed.table());
    println!("{}", readings_table(&fixed, &until));
    let t2 = settings.brake_start_secs();
    for (f, u) in fixed.controllers.iter().zip(&until.controllers) {
        for (tf, tu) in f.trials.iter().zip(&u.trials) {
            println!(
                "{:<7} seed {}: speed at t2 + 1.4 s {:+.4} m/s, J_P fixed {:.4}; until stopped: \
                 t3 - t2 = {:.4} s{}, J_P {:.4}",
                f.kind.label(),
                tf.seed,
                tf.end_speed_m_per_s,
                tf.j_p,
                tu.t3_secs - t2,
                if tu.t3_capped { " (capped)" } else { "" },
                tu.j_p,
            );
        }
    }
    let grid = fixed.stop_sensitivity(&SENSITIVITY_BANDS_M_PER_S, &SENSITIVITY_HOLDS_SECS)?;
    println!("{}", stop_sensitivity_table(&grid));
    Ok(())
}
