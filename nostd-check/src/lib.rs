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

/// One step of the motor driver's speed PI (the LQR-PI inner loop) in f32, fed one step of the
/// LQR-PI outer loop: the planar controllers link without std or an allocator.
#[unsafe(no_mangle)]
pub extern "C" fn ballbot_nostd_lqr_pi_step_f32(tilt_rad: f32, ball_rate_rad_per_s: f32) -> f32 {
    use ballbot_core::control::{
        LqrGains, LqrPiOuter, LqrPiOuterConfig, SpeedCommand, SpeedPi, SpeedPiGains,
    };
    let Ok(wip) = Wip::new(WipParams::<f32>::miapure_60kg()) else {
        return f32::NAN;
    };
    let (Ok(lqr), Ok(inner)) = (
        LqrGains::for_wip(&wip, 83.9),
        SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 83.9),
    ) else {
        return f32::NAN;
    };
    let Ok(config) = LqrPiOuterConfig::new(lqr, &inner) else {
        return f32::NAN;
    };
    let (Ok(mut outer), Ok(mut pi)) = (LqrPiOuter::new(wip, config), SpeedPi::new(inner)) else {
        return f32::NAN;
    };
    let s = Vector4::new(tilt_rad, 0.0, 0.0, ball_rate_rad_per_s);
    let o = outer.step(&s, &Vector4::zeros(), 0.0025);
    let command = SpeedCommand {
        speed_rad_per_s: o.reference_ball_rate_rad_per_s,
        feedforward_torque_nm: o.reference_torque_nm,
    };
    pi.step(ball_rate_rad_per_s, &command, 1.0 / 8000.0)
        .torque_nm
}

/// The robot loop of `ballbot-examples` (the code a firmware calls from its 400 Hz and 8 kHz
/// interrupts) on stand-in devices, in f32: the embedding example itself links without std or
/// an allocator. Returns the first omniwheel torque after one outer and one inner step.
#[unsafe(no_mangle)]
pub extern "C" fn ballbot_nostd_robot_loop_f32(pitch_rad: f32, now_us: u64) -> f32 {
    use ballbot_core::BallbotParams;
    use ballbot_core::ballbot::BallbotControllerConfig;
    use ballbot_core::command::Command;
    use ballbot_core::estimation::{EncoderSample, ImuSample};
    use ballbot_core::hal::{
        DeviceErrorKind, Imu, MonotonicClock, MotorFeedback, MotorTorques, WheelEncoders,
    };
    use ballbot_core::safety::ModeRequest;
    use ballbot_runtime::{LoopConfig, OperatorInput, RobotLoop};
    use nalgebra::Vector3;

    struct Board {
        pitch_rad: f32,
        now_us: u64,
    }
    struct Motors(f32);
    impl Imu<f32> for Board {
        type Error = DeviceErrorKind;
        fn read(&mut self) -> Result<ImuSample<f32>, DeviceErrorKind> {
            let mut s = ImuSample::upright(self.now_us);
            s.pitch_rad = self.pitch_rad;
            Ok(s)
        }
    }
    impl WheelEncoders<f32> for Board {
        type Error = DeviceErrorKind;
        fn read(&mut self) -> Result<EncoderSample<f32>, DeviceErrorKind> {
            Ok(EncoderSample::still(self.now_us))
        }
    }
    impl MotorTorques<f32> for Motors {
        type Error = DeviceErrorKind;
        fn apply(
            &mut self,
            torque_nm: &Vector3<f32>,
        ) -> Result<[MotorFeedback<f32>; 3], DeviceErrorKind> {
            // The reply to the previous setpoint, as over a bus: OW1's torque, the others idle.
            let feedback = [
                MotorFeedback::healthy(self.0, 0.0, 45.0),
                MotorFeedback::healthy(0.0, 0.0, 45.0),
                MotorFeedback::healthy(0.0, 0.0, 45.0),
            ];
            self.0 = torque_nm[0];
            Ok(feedback)
        }
        fn disable(&mut self) -> Result<(), DeviceErrorKind> {
            self.0 = 0.0;
            Ok(())
        }
    }
    impl MonotonicClock for Board {
        fn now_us(&mut self) -> u64 {
            self.now_us
        }
    }
    let Ok(config) = BallbotControllerConfig::design(&BallbotParams::<f32>::miapure_60kg()) else {
        return f32::NAN;
    };
    let board = |now_us| Board { pitch_rad, now_us };
    let Ok(mut robot) = RobotLoop::new(
        config,
        LoopConfig::miapure(),
        board(now_us),
        board(now_us),
        Motors(0.0),
        board(now_us),
    ) else {
        return f32::NAN;
    };
    robot.outer_task(&OperatorInput {
        command: Command::Stop,
        command_timestamp_us: Some(now_us),
        request: ModeRequest::None,
    });
    robot.inner_task().output.torque_nm[0]
}

/// One step of the 3D ballbot controller in f32 (supervisor, estimation, shaping, three
/// planes, kinematics: the 400 Hz outer step), with traction-aware control on (its envelope
/// is built here, its slip monitor runs), and one 8 kHz inner step of its three motor PIs:
/// the whole 3D controller links without std or an allocator. Returns omniwheel 1's torque.
#[unsafe(no_mangle)]
pub extern "C" fn ballbot_nostd_ballbot_3d_step_f32(
    now_us: u64,
    roll_rad: f32,
    pitch_rad: f32,
    wheel_speed_rad_per_s: f32,
) -> f32 {
    use ballbot_core::BallbotParams;
    use ballbot_core::ballbot::{
        BallbotController, BallbotControllerConfig, MotorSpeedLoop, OuterInput,
    };
    use ballbot_core::command::{Command, VelocityCommand};
    use ballbot_core::estimation::{EncoderSample, ImuSample};
    use ballbot_core::safety::ModeRequest;
    use nalgebra::Vector3;
    let Ok(designed) = BallbotControllerConfig::design(&BallbotParams::<f32>::miapure_60kg())
    else {
        return f32::NAN;
    };
    let config = designed
        .with_traction_control()
        .with_balance_point_estimation();
    let (Ok(mut outer), Ok(mut inner)) =
        (BallbotController::new(config), MotorSpeedLoop::new(&config))
    else {
        return f32::NAN;
    };
    let mut imu = ImuSample::upright(now_us);
    imu.roll_rad = roll_rad;
    imu.pitch_rad = pitch_rad;
    let mut encoders = EncoderSample::still(now_us);
    encoders.wheel_speeds_rad_per_s = Vector3::new(wheel_speed_rad_per_s, 0.0, 0.0);
    let out = outer.step(&OuterInput {
        now_us,
        imu,
        encoders,
        command: Command::Velocity(VelocityCommand::zero()),
        command_timestamp_us: Some(now_us),
        request: ModeRequest::Arm,
    });
    inner.set_references(&out.motors);
    inner
        .step(&encoders.wheel_speeds_rad_per_s, 1.0 / 8000.0)
        .torque_nm[0]
}
