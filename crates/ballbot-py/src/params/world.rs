//! The 3D world's parameter classes: the contact and its realistic mechanisms, sensors,
//! failure limits, the motor driver, and `WorldParams` itself.

use super::*;

/// Validates a part of the world's parameters inside the MiaPURE world, so that the error names
/// it as `WorldParams.validate` does (`contact.kinetic_friction_ratio`).
fn check_world_part(py: Python<'_>, set: impl FnOnce(&mut WorldParams)) -> PyResult<()> {
    let mut world = WorldParams::miapure_60kg();
    set(&mut world);
    world.validate().map_err(|e| world_error(py, e))
}

impl CoreParams for ContactParams {
    const NAME: &'static str = "ContactParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        check_world_part(py, |w| w.contact = *self)
    }
}

impl CoreParams for RollerParams {
    const NAME: &'static str = "RollerParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        check_world_part(py, |w| w.contact.rollers = *self)
    }
}

impl CoreParams for AxleLossParams {
    const NAME: &'static str = "AxleLossParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        check_world_part(py, |w| w.contact.axle_loss = *self)
    }
}

/// The ideal contact with the rubber coating's stiffness and damping for MiaPURE with 60 kg.
fn contact_rubber_coated_miapure_60kg() -> ContactParams {
    ContactParams::rubber_coated(&BallbotParams::miapure_60kg(), &RubberLayer::miapure())
}

py_params! {
    /// Roller gaps of each omniwheel (`ballbot_sim::world::RollerParams`): `count` rollers
    /// (0: a continuous rim) separated by gaps of `gap_width_m`.
    PyRollerParams(RollerParams, "RollerParams", default = RollerParams::none) {
        floats { gap_width_m }
        ints { count: u32 }
        arrays {}
        nested {}
    }
    presets {
        "none" => RollerParams::none,
        "miapure" => RollerParams::miapure,
    }
}

py_params! {
    /// Roller rolling resistance and pin friction along each wheel's axle
    /// (`ballbot_sim::world::AxleLossParams`).
    PyAxleLossParams(AxleLossParams, "AxleLossParams", default = AxleLossParams::none) {
        floats {
            rolling_resistance, pin_friction, pin_radius_m, roller_radius_m,
            regularisation_speed_m_per_s,
        }
        arrays {}
        nested {}
    }
    presets {
        "none" => AxleLossParams::none,
        "miapure" => AxleLossParams::miapure,
    }
    methods {
        /// The force per unit load once the axle slip exceeds the regularisation speed,
        /// `C_rr + mu_b r_pin / r_roller`.
        fn coefficient(&self) -> f64 {
            self.inner.coefficient()
        }
    }
}

impl CoreParams for SensorParams {
    const NAME: &'static str = "SensorParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        check_world_part(py, |w| w.sensors = *self)
    }
}

impl CoreParams for ImuParams {
    const NAME: &'static str = "ImuParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        check_world_part(py, |w| w.sensors.imu = *self)
    }
}

impl CoreParams for FailureParams {
    const NAME: &'static str = "FailureParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        check_world_part(py, |w| w.failure = *self)
    }
}

impl CoreParams for DriverParams {
    const NAME: &'static str = "DriverParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        self.validate().map_err(|e| world_error(py, e))
    }
}

impl CoreParams for TransmissionParams {
    const NAME: &'static str = "TransmissionParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        check_world_part(py, |w| w.transmission = *self)
    }
}

impl CoreParams for FloorParams {
    const NAME: &'static str = "FloorParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        check_world_part(py, |w| w.floor = *self)
    }
}

impl CoreParams for WorldParams {
    const NAME: &'static str = "WorldParams";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        self.validate().map_err(|e| world_error(py, e))
    }
}

/// MiaPURE without payload in the default world.
fn world_miapure_unloaded() -> WorldParams {
    WorldParams::with_robot(BallbotParams::miapure_unloaded())
}

/// MiaPURE with 60 kg in the ideal world (`WorldParams::ideal`).
fn world_ideal_miapure_60kg() -> WorldParams {
    WorldParams::ideal(BallbotParams::miapure_60kg())
}

py_params! {
    /// The compliant omniwheel-ball contact of the 3D world
    /// (`ballbot_sim::world::ContactParams`): the normal law (`normal_law` `"linear"`, a
    /// spring-damper, or `"coating"`, the ball coating's law over its whole range), a
    /// tangential stick spring-damper along the rolling direction, kinetic over static
    /// friction while slipping.
    PyContactParams(ContactParams, "ContactParams", default = ContactParams::default) {
        floats {
            roller_radius_m, normal_stiffness_n_per_m, normal_damping_n_s_per_m,
            traction_stiffness_n_per_m, traction_damping_n_s_per_m, kinetic_friction_ratio,
        }
        names { normal_law }
        arrays {}
        nested { rollers: PyRollerParams, axle_loss: PyAxleLossParams }
    }
    presets {
        "default" => ContactParams::default,
        "ideal" => ContactParams::ideal,
        "coating" => ContactParams::coating,
        "rubber_coated_miapure_60kg" => contact_rubber_coated_miapure_60kg,
    }
}

py_params! {
    /// The IMU of the 3D world (`ballbot_sim::world::ImuParams`): `model` `"truth"` (the true
    /// attitude plus white noise, the ideal world's) or `"attitude_filter"` (gyro with bias
    /// and noise, accelerometer, an accelerometer-aided attitude filter with the time constant
    /// `filter_time_constant_secs`, and an output delay; preset `"vn100"`, the default
    /// world's). Errors name the field (`sensors.imu.sample_rate_hz`).
    PyImuParams(ImuParams, "ImuParams", default = ImuParams::truth) {
        floats {
            sample_rate_hz, output_delay_secs, filter_time_constant_secs,
            gyro_noise_density_rad_per_s_per_sqrt_hz, gyro_bias_rad_per_s,
            gyro_bias_correlation_time_secs, accel_noise_density_m_per_s2_per_sqrt_hz,
        }
        names { model }
        arrays {}
        nested {}
    }
    presets {
        "truth" => ImuParams::truth,
        "vn100" => ImuParams::vn100,
    }
    methods {
        /// The filter's tilt error (rad, towards the apparent vertical) `t_secs` after a
        /// constant horizontal acceleration starts, the body held upright.
        fn tilt_error_under_acceleration_rad(
            &self,
            accel_m_per_s2: f64,
            gravity_m_per_s2: f64,
            t_secs: f64,
        ) -> f64 {
            self.inner
                .tilt_error_under_acceleration_rad(accel_m_per_s2, gravity_m_per_s2, t_secs)
        }
    }
}

py_params! {
    /// Sensors of the 3D world (`ballbot_sim::world::SensorParams`): the IMU (`imu`), the
    /// link latency to the motor drivers, Gaussian noise from a generator seeded with `seed`,
    /// quantised encoders. Presets `"default"` (the ideal world's: the true attitude plus
    /// noise, no latency) and `"miapure"` (the VN-100 and the CAN link, the default world's).
    PySensorParams(SensorParams, "SensorParams", default = SensorParams::default) {
        floats { tilt_noise_rad, gyro_noise_rad_per_s, link_latency_secs }
        ints { seed: u64, encoder_counts_per_rev: u32 }
        arrays {}
        nested { imu: PyImuParams }
    }
    presets {
        "default" => SensorParams::default,
        "miapure" => SensorParams::miapure,
    }
}

py_params! {
    /// When a 3D world run counts as failed (`ballbot_sim::world::FailureParams`): tilt,
    /// sustained slip, lift-off.
    PyFailureParams(FailureParams, "FailureParams", default = FailureParams::default) {
        floats {
            max_tilt_rad, slip_speed_threshold_m_per_s, max_slip_duration_secs, lift_off_force_n,
            max_lift_off_duration_secs,
        }
        arrays {}
        nested {}
    }
    presets {
        "default" => FailureParams::default,
    }
}

py_params! {
    /// The motor driver between torque command and wheel
    /// (`ballbot_sim::world::DriverParams`): `model` `"ideal"` (the actuator's straight
    /// torque-speed line, the default) or `"odrive"` (the ODrive v3.6 firmware's current,
    /// voltage and velocity limits and its overspeed trip). Errors name the field
    /// (`driver.current_limit_a`).
    PyDriverParams(DriverParams, "DriverParams", default = DriverParams::ideal) {
        floats {
            bus_voltage_v, max_modulation, motor_kv_rpm_per_v, phase_resistance_ohm,
            current_limit_a, current_limit_margin_a, requested_current_range_a,
            vel_limit_turn_per_s, vel_limit_tolerance, vel_gain_nm_s_per_turn,
        }
        bools { enable_torque_mode_vel_limit, enable_overspeed_error }
        names { model }
        arrays {}
        nested {}
    }
    presets {
        "ideal" => DriverParams::ideal,
        "odrive_v36_factory" => DriverParams::odrive_v36_factory,
        "miapure" => DriverParams::miapure,
    }
    methods {
        /// `K_t` (N m/A at the rotor): the ODrive's `8.27 / KV`.
        fn torque_constant_nm_per_a(&self) -> f64 {
            self.inner.torque_constant_nm_per_a()
        }

        /// The q-axis current limit in force (A): `current_limit_a` capped by the hardware
        /// range that `requested_current_range_a` selects.
        fn effective_current_limit_a(&self) -> f64 {
            self.inner.effective_current_limit_a()
        }
    }
}

py_params! {
    /// The drivetrain between each motor and its omniwheel
    /// (`ballbot_sim::world::TransmissionParams`): gearbox stiction and Coulomb friction
    /// (Karnopp), an elastomeric coupling (stiffness, damping) and backlash, all at the gearbox
    /// output. `coupling_stiffness_nm_per_rad = 0` is the rigid drivetrain (preset `"rigid"`, the
    /// ideal world's); `"miapure"` is the default world's. Errors name the field
    /// (`transmission.backlash_rad`).
    PyTransmissionParams(TransmissionParams, "TransmissionParams", default = TransmissionParams::rigid) {
        floats {
            stiction_torque_nm, coulomb_torque_nm, stick_window_rad_per_s, stick_settle_time_secs,
            coupling_stiffness_nm_per_rad, coupling_damping_nm_s_per_rad, backlash_rad,
        }
        arrays {}
        nested {}
    }
    presets {
        "rigid" => TransmissionParams::rigid,
        "miapure" => TransmissionParams::miapure,
    }
}

py_params! {
    /// The floor and the ball coating's compliant contact on it
    /// (`ballbot_sim::world::FloorParams`): the coating's hardness, thickness and loss factor
    /// (Hertz's plus the thin bonded layer's law, hysteretic damping, friction in a cone), the
    /// kinetic friction ratio, and the floor's inclination. Preset `"miapure"` (level) in both
    /// worlds. Errors name the field (`floor.slope_rad`).
    PyFloorParams(FloorParams, "FloorParams", default = FloorParams::miapure) {
        floats {
            coating_shore_a_hardness, coating_thickness_m, coating_loss_factor,
            kinetic_friction_ratio, slope_rad, slope_heading_deg,
        }
        arrays {}
        nested {}
    }
    presets {
        "miapure" => FloorParams::miapure,
    }
}

py_params! {
    /// Everything the 3D world needs (`ballbot_sim::world::WorldParams`): the robot
    /// (`BallbotParams`) plus the contact, wheel and rotor inertia, floor friction, chassis,
    /// physics step, sensors, failure limits, the motor driver and the drivetrain. Errors name
    /// the field
    /// (`contact.kinetic_friction_ratio`).
    PyWorldParams(WorldParams, "WorldParams", default = WorldParams::miapure_60kg) {
        floats {
            wheel_inertia_kg_m2, rotor_inertia_kg_m2, wheel_damping_nm_s_per_rad,
            rolling_resistance, spin_friction_m, chassis_half_width_m, chassis_height_m, dt_secs,
        }
        ints { rigid_step_ratio: u32 }
        arrays {}
        nested {
            robot: PyBallbotParams,
            contact: PyContactParams,
            sensors: PySensorParams,
            failure: PyFailureParams,
            driver: PyDriverParams,
            transmission: PyTransmissionParams,
            floor: PyFloorParams,
        }
    }
    presets {
        "miapure_60kg" => WorldParams::miapure_60kg,
        "miapure_unloaded" => world_miapure_unloaded,
        "ideal_miapure_60kg" => world_ideal_miapure_60kg,
    }
    methods {
        /// The given robot in the default world (the realistic one: roller gaps, roller
        /// losses along the axle, the rubber coating, the ODrive driver, the drivetrain with
        /// gearbox stiction, coupling and backlash).
        #[staticmethod]
        fn with_robot(py: Python<'_>, robot: PyBallbotParams) -> PyResult<Self> {
            let inner = WorldParams::with_robot(robot.inner);
            inner.check(py)?;
            Ok(Self { inner })
        }

        /// The given robot in the ideal world: stiff continuous-rim contacts, no forces along
        /// the axle, the actuator's straight torque-speed line, a rigid drivetrain (the first
        /// releases' world).
        #[staticmethod]
        fn ideal(py: Python<'_>, robot: PyBallbotParams) -> PyResult<Self> {
            let inner = WorldParams::ideal(robot.inner);
            inner.check(py)?;
            Ok(Self { inner })
        }

        /// Reflected inertia of one wheel: wheel plus rotor times gear ratio squared (kg m^2).
        fn reflected_wheel_inertia_kg_m2(&self) -> f64 {
            self.inner.reflected_wheel_inertia_kg_m2()
        }

        /// The largest `rigid_step_ratio` these parameters allow (the rigid step's phase on the
        /// ball's contact mode at most 1.2 rad, and at most 40).
        fn max_rigid_step_ratio(&self) -> u32 {
            self.inner.max_rigid_step_ratio()
        }
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyRollerParams>()?;
    m.add_class::<PyAxleLossParams>()?;
    m.add_class::<PyContactParams>()?;
    m.add_class::<PyImuParams>()?;
    m.add_class::<PySensorParams>()?;
    m.add_class::<PyFailureParams>()?;
    m.add_class::<PyDriverParams>()?;
    m.add_class::<PyTransmissionParams>()?;
    m.add_class::<PyFloorParams>()?;
    m.add_class::<PyWorldParams>()?;
    Ok(())
}
