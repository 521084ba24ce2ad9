use super::*;

const DT: f64 = 1.0 / 8000.0;
const G: f64 = 9.81;

/// The VN-100 preset without noise or bias: only the filter acts.
fn noiseless() -> ImuParams {
    ImuParams {
        gyro_noise_density_rad_per_s_per_sqrt_hz: 0.0,
        gyro_bias_rad_per_s: 0.0,
        accel_noise_density_m_per_s2_per_sqrt_hz: 0.0,
        ..ImuParams::vn100()
    }
}

/// The body upright and not turning, its centre of mass at `velocity` at world step `k`.
fn upright(k: u64, velocity: Vector3<f64>) -> ImuTruth {
    ImuTruth {
        time_secs: k as f64 * DT,
        orientation: UnitQuaternion::identity(),
        body_rate_rad_per_s: Vector3::zeros(),
        velocity_m_per_s: velocity,
        gravity_m_per_s2: Vector3::new(0.0, 0.0, -G),
    }
}

/// Pitch of the estimate (rad; > 0 leans towards +x).
fn pitch(r: &ImuReading) -> f64 {
    r.orientation.euler_angles().1
}

#[test]
fn under_a_constant_acceleration_the_tilt_error_follows_the_filters_solution() {
    let p = noiseless();
    let accel = 1.5;
    let mut imu = AttitudeFilter::new(p, DT, 1);
    let mut worst: f64 = 0.0;
    // Ten time constants: the error has converged to the lean.
    for k in 0..=(10.0 * p.filter_time_constant_secs / DT) as u64 {
        let v = Vector3::new(accel * k as f64 * DT, 0.0, 0.0);
        imu.record(&upright(k, v));
        let r = imu.reading().unwrap();
        // The estimate leans away from the acceleration: the apparent vertical.
        let predicted = -p.tilt_error_under_acceleration_rad(accel, G, r.time_secs);
        worst = worst.max((pitch(&r) - predicted).abs());
    }
    let lean = accel.atan2(G);
    // The discrete filter (800 Hz against tau = 2.3 s) tracks the continuous solution.
    assert!(worst < 2e-3 * lean, "worst {worst:.3e} of {lean:.4}");
    let end = imu.reading().unwrap();
    assert!((pitch(&end) + lean).abs() < 5e-3 * lean, "{}", pitch(&end));
    assert!(end.orientation.euler_angles().0.abs() < 1e-12);
}

#[test]
fn a_gyro_bias_leaves_a_steady_tilt_error_of_tau_times_the_bias() {
    let p = ImuParams {
        gyro_bias_rad_per_s: 2e-3,
        gyro_bias_correlation_time_secs: 1e9,
        ..noiseless()
    };
    let mut imu = AttitudeFilter::new(p, DT, 3);
    for k in 0..(10.0 * p.filter_time_constant_secs / DT) as u64 {
        imu.record(&upright(k, Vector3::zeros()));
    }
    let bias = imu.bias_rad_per_s;
    assert!(bias.norm() > 1e-4, "the seed drew a bias: {bias:?}");
    let (roll, pitch, _) = imu.reading().unwrap().orientation.euler_angles();
    let tau = p.filter_time_constant_secs;
    // de/dt = b - e / tau about x and y.
    assert!(
        (roll - tau * bias.x).abs() < 1e-2 * bias.norm(),
        "{roll} {bias:?}"
    );
    assert!(
        (pitch - tau * bias.y).abs() < 1e-2 * bias.norm(),
        "{pitch} {bias:?}"
    );
}

#[test]
fn the_gyro_noise_and_the_bias_have_their_stated_spread() {
    let p = ImuParams {
        gyro_bias_rad_per_s: 1e-3,
        gyro_bias_correlation_time_secs: 0.05,
        ..ImuParams::vn100()
    };
    let mut imu = AttitudeFilter::new(p, DT, 11);
    let (mut rates, mut biases) = (Vec::new(), Vec::new());
    let mut last_time = -1.0;
    for k in 0..(100.0 / DT) as u64 {
        imu.record(&upright(k, Vector3::zeros()));
        let r = imu.reading().unwrap();
        if r.time_secs > last_time {
            last_time = r.time_secs;
            rates.push(r.body_rate_rad_per_s.x - imu.bias_rad_per_s.x);
            biases.push(imu.bias_rad_per_s.x);
        }
    }
    let std = |x: &[f64]| {
        let m = x.iter().sum::<f64>() / x.len() as f64;
        (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
    };
    // The delayed reading's noise against the current bias: the bias moves little in the
    // two samples between them (T_b = 0.05 s, 400 samples of it at 800 Hz).
    let noise = p.gyro_noise_density_rad_per_s_per_sqrt_hz * (400.0_f64).sqrt();
    assert!(
        (std(&rates) / noise - 1.0).abs() < 0.05,
        "{} {noise}",
        std(&rates)
    );
    assert!((std(&biases) / 1e-3 - 1.0).abs() < 0.1, "{}", std(&biases));
}

#[test]
fn the_reading_is_the_output_delay_old() {
    for delay_samples in [0_u32, 2, 7] {
        let p = ImuParams {
            output_delay_secs: f64::from(delay_samples) / 800.0,
            ..ImuParams::vn100()
        };
        let mut imu = AttitudeFilter::new(p, DT, 0);
        assert!(imu.reading().is_none());
        for k in 1..=8000 {
            imu.record(&upright(k, Vector3::zeros()));
        }
        let lag = 1.0 - imu.reading().unwrap().time_secs;
        assert!(
            (lag - f64::from(delay_samples) / 800.0).abs() < 1e-9,
            "{lag}"
        );
    }
}

#[test]
fn validation_names_the_field() {
    let field = |p: ImuParams| match p.validate(DT) {
        Err(WorldError::InvalidParameter { field, .. }) => field,
        other => panic!("{other:?}"),
    };
    let p = ImuParams::vn100();
    assert!(p.validate(DT).is_ok());
    let odd_rate = ImuParams {
        sample_rate_hz: 700.0,
        ..p
    };
    assert_eq!(field(odd_rate), "sensors.imu.sample_rate_hz");
    // The truth model does not sample: any world step will do.
    let truth = ImuParams {
        sample_rate_hz: 700.0,
        ..ImuParams::truth()
    };
    assert!(truth.validate(DT).is_ok());
    assert!(ImuParams::truth().validate(1.0 / 7000.0).is_ok());
    let long_delay = ImuParams {
        output_delay_secs: 0.1,
        ..p
    };
    assert_eq!(field(long_delay), "sensors.imu.output_delay_secs");
    let no_tau = ImuParams {
        filter_time_constant_secs: f64::NAN,
        ..p
    };
    assert_eq!(field(no_tau), "sensors.imu.filter_time_constant_secs");
}
