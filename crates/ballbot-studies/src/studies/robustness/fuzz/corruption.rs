//! What a fuzz episode's bursts of hostile inputs corrupt ([`Target`]), and how.

use super::hostile::{hostile, index, symmetric, unit};
use super::rig::{INNER_PER_OUTER, InnerFault};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::estimation::{EncoderSample, ImuSample};
use rand_chacha::ChaCha8Rng;

/// What a burst corrupts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Target {
    /// An IMU field (roll, pitch, yaw, three rates).
    Imu(usize),
    /// An encoder speed at the outer tick.
    Encoder(usize),
    /// The IMU stamp: ahead of the clock, stalled, or behind it.
    ImuStamp(usize),
    /// The encoder stamp, likewise.
    EncoderStamp(usize),
    /// The command link's stamp: none, stalled.
    CommandStamp,
    /// An encoder sample in the 8 kHz loop.
    InnerEncoder(usize),
    /// A burst of 9 to 20 wrong encoder samples in the 8 kHz loop (longer than the guard's
    /// hold of 1 ms), one value within the encoder's range.
    InnerBurst(usize),
    /// The first encoder sample in the 8 kHz loop after the motors are enabled (item 7).
    FirstAfterEnable,
    /// The 8 kHz loop's step length.
    InnerDt,
}

impl Target {
    /// Which sensor the target is, for the tallies.
    pub(super) fn sensor(self) -> &'static str {
        match self {
            Self::Imu(_) | Self::ImuStamp(_) => "IMU at the outer tick",
            Self::Encoder(_) | Self::EncoderStamp(_) => "encoder at the outer tick",
            Self::CommandStamp => "command link",
            Self::InnerEncoder(_) | Self::InnerBurst(_) | Self::InnerDt => "the 8 kHz loop",
            Self::FirstAfterEnable => "the 8 kHz loop's first sample after enabling",
        }
    }

    pub(super) fn random(rng: &mut ChaCha8Rng) -> Self {
        match index(rng, 9) {
            0 | 1 => Self::Imu(index(rng, 6)),
            2 => Self::Encoder(index(rng, 3)),
            3 => Self::ImuStamp(index(rng, 3)),
            4 => Self::EncoderStamp(index(rng, 3)),
            5 => Self::CommandStamp,
            6 => Self::InnerEncoder(index(rng, 3)),
            7 => Self::InnerBurst(index(rng, 3)),
            _ => Self::InnerDt,
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn apply(
        self,
        rng: &mut ChaCha8Rng,
        config: &BallbotControllerConfig<f64>,
        imu: &mut ImuSample<f64>,
        encoders: &mut EncoderSample<f64>,
        command_ts: &mut Option<u64>,
        inner: &mut Option<InnerFault>,
        now_us: u64,
        last_imu_stamp: u64,
    ) {
        let stamp = |rng: &mut ChaCha8Rng, which: usize| match which {
            0 => now_us.saturating_add(1 + (unit(rng) * 3.6e9) as u64),
            1 => last_imu_stamp,
            _ => now_us.saturating_sub(1 + (unit(rng) * 1e7) as u64),
        };
        match self {
            Self::Imu(i) => {
                let v = hostile(rng);
                match i {
                    0 => imu.roll_rad = v,
                    1 => imu.pitch_rad = v,
                    2 => imu.yaw_rad = v,
                    j => imu.angular_velocity_rad_per_s[j - 3] = v,
                }
            }
            Self::Encoder(w) => encoders.wheel_speeds_rad_per_s[w] = hostile(rng),
            Self::ImuStamp(which) => imu.timestamp_us = stamp(rng, which),
            Self::EncoderStamp(which) => encoders.timestamp_us = stamp(rng, which),
            Self::CommandStamp => *command_ts = None,
            Self::InnerEncoder(w) => {
                *inner = Some(InnerFault::Encoder {
                    step: index(rng, INNER_PER_OUTER),
                    wheel: w,
                    value: hostile(rng),
                });
            }
            Self::InnerBurst(w) => {
                let len = 9 + index(rng, 12);
                *inner = Some(InnerFault::Burst {
                    from: index(rng, INNER_PER_OUTER + 1 - len),
                    len,
                    wheel: w,
                    value: symmetric(rng, config.safety.encoder_range_rad_per_s),
                });
            }
            Self::FirstAfterEnable => {}
            Self::InnerDt => {
                *inner = Some(InnerFault::Dt {
                    dt_secs: hostile(rng),
                })
            }
        }
    }
}
