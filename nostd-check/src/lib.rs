//! Links ballbot-core into a `#![no_std]` staticlib with no allocator: the proof that the core
//! could be flashed onto a microcontroller. Each exported function forces the generic code to be
//! instantiated for `f32` (microcontrollers) and `f64`.
#![no_std]

use ballbot_core::{Wip, WipParams};
use nalgebra::Vector4;

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo<'_>) -> ! {
    loop {}
}

/// One RK4 step of the MiaPURE WIP in f32, as firmware would run it.
#[unsafe(no_mangle)]
pub extern "C" fn ballbot_nostd_wip_step_f32(tilt_rad: f32, torque_nm: f32) -> f32 {
    match Wip::new(WipParams::<f32>::miapure_60kg()) {
        Ok(wip) => {
            let s = Vector4::new(tilt_rad, 0.0, 0.0, 0.0);
            let next = ballbot_core::rk4_step(|x| wip.derivative(x, torque_nm), &s, 0.0025);
            next[0]
        }
        Err(_) => f32::NAN,
    }
}

/// The same in f64.
#[unsafe(no_mangle)]
pub extern "C" fn ballbot_nostd_wip_step_f64(tilt_rad: f64, torque_nm: f64) -> f64 {
    match Wip::new(WipParams::<f64>::miapure_60kg()) {
        Ok(wip) => {
            let s = Vector4::new(tilt_rad, 0.0, 0.0, 0.0);
            let next = ballbot_core::rk4_step(|x| wip.derivative(x, torque_nm), &s, 0.0025);
            next[0]
        }
        Err(_) => f64::NAN,
    }
}
