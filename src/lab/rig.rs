//! The lab's two-cart rig on the PC104 card, [`MassSpringRig`], and its
//! [`Calibration`].

use nalgebra::{SVector, vector};

use crate::data::Schema;
use crate::hw::{ENCODER_CHANNELS, EppPort, HwError, MAX_DUTY, PWM_CHANNELS, Pc104, Rig};

/// How the rig's counts and volts map to SI, and which channels are wired
/// where.
///
/// The default is the lab's rig as [`SimulatedRig`](super::SimulatedRig)
/// models it: 80 mm per 8192 counts (9.765625 µm per count), both encoders
/// counting up when the carts move away from the wall, 24 V full scale, the
/// motor on PWM channel 0, cart 1 on encoder 0, cart 2 on encoder 1, travel
/// limits ±0.15 m on both carts.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::Calibration;
/// let cal = Calibration::default();
/// assert_eq!(cal.metres_per_count * 8192.0, 0.080);
/// let flipped = Calibration { sign: [1.0, -1.0], ..cal };
/// assert!(flipped.validate().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calibration {
    /// Cart travel per encoder count, m (> 0).
    pub metres_per_count: f64,
    /// Sign of each encoder (cart 1, cart 2): +1 when counting up means the
    /// cart moves away from the wall, −1 otherwise.
    pub sign: [f64; 2],
    /// Motor voltage at 100 % duty, V (> 0); commands saturate at ±this.
    pub volts_full_scale: f64,
    /// The PWM channel driving the motor (0–3).
    pub pwm_channel: usize,
    /// The encoder channels of cart 1 and cart 2 (0–3, distinct).
    pub encoder_channels: [usize; 2],
    /// Software travel limits of cart 1 and cart 2, m (> 0, symmetric about
    /// the position where the counters were cleared).
    pub travel_limits: [f64; 2],
}

impl Default for Calibration {
    fn default() -> Self {
        Self {
            metres_per_count: 0.080 / 8192.0,
            sign: [1.0, 1.0],
            volts_full_scale: 24.0,
            pwm_channel: 0,
            encoder_channels: [0, 1],
            travel_limits: [0.15, 0.15],
        }
    }
}

impl Calibration {
    /// Checks every field.
    ///
    /// # Errors
    ///
    /// [`HwError::InvalidConfig`] naming the first bad field.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::HwError, lab::Calibration};
    /// let bad = Calibration { sign: [1.0, 0.5], ..Calibration::default() };
    /// assert!(matches!(bad.validate(), Err(HwError::InvalidConfig { name: "sign", .. })));
    /// ```
    pub fn validate(&self) -> Result<(), HwError> {
        let positive = [
            ("metres_per_count", self.metres_per_count),
            ("volts_full_scale", self.volts_full_scale),
            ("travel_limits", self.travel_limits[0]),
            ("travel_limits", self.travel_limits[1]),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(invalid(name, value, "must be finite and > 0"));
            }
        }
        for s in self.sign {
            if s != 1.0 && s != -1.0 {
                return Err(invalid("sign", s, "must be +1 or -1"));
            }
        }
        if self.pwm_channel >= PWM_CHANNELS {
            return Err(invalid(
                "pwm_channel",
                self.pwm_channel as f64,
                "must be 0–3",
            ));
        }
        let [e1, e2] = self.encoder_channels;
        if e1 >= ENCODER_CHANNELS || e2 >= ENCODER_CHANNELS || e1 == e2 {
            return Err(invalid(
                "encoder_channels",
                e2 as f64,
                "must be two distinct channels 0–3",
            ));
        }
        Ok(())
    }
}

fn invalid(name: &'static str, value: f64, reason: &'static str) -> HwError {
    HwError::InvalidConfig {
        name,
        value,
        reason,
    }
}

/// The lab's two-cart rig on a [`Pc104`] card: counts to metres, volts to
/// PWM duty, with the safety the rig needs. A [`Rig`] with one input (the
/// motor, V) and four measurements `[x1, v1, x2, v2]` (m, m/s), named by
/// [`schema`](super::schema).
///
/// - [`read_state`](Self::read_state) latches both counters **and kicks the
///   watchdog** in one control write, reads cart 1's and cart 2's counters,
///   and returns `[x1, v1, x2, v2]`; speeds are backward differences of
///   the counts over `period` (as the lab: "speeds come from counting pulses
///   over the sampling period"), so read exactly once per period; the first
///   read reports zero speeds. A cart beyond its travel limit halts the rig
///   and returns [`HwError::TravelLimit`].
/// - [`apply_voltage`](Self::apply_voltage) saturates to
///   ±`volts_full_scale` and quantises to the card's 0.1 % duty steps; a
///   non-finite command halts the rig and returns
///   [`HwError::InvalidCommand`].
/// - Dropping the rig sets the PWM to zero (errors ignored: there is no one
///   left to tell).
///
/// Nothing allocates in `read_state` or `apply_voltage`. The simulated rig
/// in one call is [`SimulatedRig::rig`](super::SimulatedRig::rig).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Clock, VirtualClock};
/// use ctrlab::lab::SimulatedRig;
///
/// let clock = VirtualClock::new();
/// let mut rig = SimulatedRig::default().rig(&Clock::Virtual(clock.clone()))?;
/// assert_eq!(rig.apply_voltage(100.0)?, 24.0); // saturates at 24 V
/// assert_eq!(rig.card().port().pwm_duty(0), 1000);
/// clock.advance(0.02)?;
/// let x = rig.read_state()?;
/// assert!(x[2] > 0.0 && x[2] < 0.15);
/// assert!(rig.apply_voltage(f64::NAN).is_err());
/// assert_eq!(rig.card().port().pwm_duty(0), 0); // halted
/// # Ok::<(), ctrlab::hw::HwError>(())
/// ```
#[derive(Debug)]
pub struct MassSpringRig<P: EppPort> {
    card: Pc104<P>,
    calibration: Calibration,
    period: f64,
    previous: Option<[i64; 2]>,
}

impl<P: EppPort> MassSpringRig<P> {
    /// The rig on `card` with `calibration`, read every `period` seconds.
    /// Talks to the card only when used.
    ///
    /// # Errors
    ///
    /// [`HwError::InvalidConfig`] for an invalid calibration or a period
    /// that is not finite and > 0.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{HwErrorKind, Pc104, testing::RegisterFile};
    /// use ctrlab::lab::{Calibration, MassSpringRig};
    /// let rig = MassSpringRig::new(Pc104::new(RegisterFile::new()), Calibration::default(), 0.002)?;
    /// assert_eq!(rig.period(), 0.002);
    /// let bad = MassSpringRig::new(Pc104::new(RegisterFile::new()), Calibration::default(), 0.0);
    /// assert_eq!(bad.unwrap_err().kind(), HwErrorKind::InvalidConfig);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn new(card: Pc104<P>, calibration: Calibration, period: f64) -> Result<Self, HwError> {
        calibration.validate()?;
        if !(period.is_finite() && period > 0.0) {
            return Err(invalid("period", period, "must be finite and > 0 s"));
        }
        Ok(Self {
            card,
            calibration,
            period,
            previous: None,
        })
    }

    /// The card driver.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.card().port().voltage(), 0.0);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn card(&self) -> &Pc104<P> {
        &self.card
    }

    /// The card driver, mutably (to clear counters, probe the ID, …).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{Clock, SIMULATED_CARD_ID}, lab::SimulatedRig};
    /// let mut rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.card_mut().probe_id(SIMULATED_CARD_ID)?, SIMULATED_CARD_ID);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn card_mut(&mut self) -> &mut Pc104<P> {
        &mut self.card
    }

    /// The calibration.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.calibration().volts_full_scale, 24.0);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// The sampling period the speeds are computed over, s.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let rig = SimulatedRig { period: 0.001, ..Default::default() }.rig(&Clock::RealTime)?;
    /// assert_eq!(rig.period(), 0.001);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn period(&self) -> f64 {
        self.period
    }

    /// The duty for `volts` (finite): saturated, quantised to 0.1 %.
    fn duty(&self, volts: f64) -> i16 {
        let full = self.calibration.volts_full_scale;
        let fraction = volts.clamp(-full, full) / full;
        (fraction * f64::from(MAX_DUTY)).round() as i16
    }

    /// Samples the state `[x1, v1, x2, v2]` (m, m/s): latches the counters
    /// and kicks the watchdog in one control write, then reads both
    /// counters. [`Rig::read`] is this.
    ///
    /// # Errors
    ///
    /// Port errors; [`HwError::TravelLimit`] (after halting) when a cart is
    /// beyond its limit.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// use nalgebra::vector;
    /// let mut rig = SimulatedRig { initial_state: vector![0.001, 0.0, 0.002, 0.0], ..Default::default() }
    ///     .rig(&Clock::RealTime)?;
    /// let x = rig.read_state()?; // the counters count from where they were cleared: 0
    /// assert_eq!(x[3], 0.0);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn read_state(&mut self) -> Result<SVector<f64, 4>, HwError> {
        let cal = self.calibration;
        self.card.latch_and_kick()?;
        let counts = [
            self.card.read_counter(cal.encoder_channels[0])?,
            self.card.read_counter(cal.encoder_channels[1])?,
        ];
        let previous = self.previous.replace(counts).unwrap_or(counts);
        let mut x = SVector::<f64, 4>::zeros();
        for cart in 0..2 {
            let scale = cal.sign[cart] * cal.metres_per_count;
            x[2 * cart] = counts[cart] as f64 * scale;
            x[2 * cart + 1] = (counts[cart] - previous[cart]) as f64 * scale / self.period;
        }
        for cart in 0..2 {
            let (position, limit) = (x[2 * cart], cal.travel_limits[cart]);
            if position.abs() > limit {
                // The breach is the error to report; should the halt fail
                // too, the caller's own halt or the card's watchdog follows.
                self.halt_motor().ok();
                return Err(HwError::TravelLimit {
                    axis: cart + 1,
                    position,
                    limit,
                });
            }
        }
        Ok(x)
    }

    /// Applies `volts` to the motor, saturated to ±`volts_full_scale` and
    /// quantised to the card's 0.1 % duty steps, and returns the voltage
    /// actually applied, V. [`Rig::apply`] is this.
    ///
    /// # Errors
    ///
    /// Port errors; [`HwError::InvalidCommand`] (after halting) for a
    /// non-finite voltage.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let mut rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.apply_voltage(1.01)?, 1.008); // 42 duty steps of 24 mV
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn apply_voltage(&mut self, volts: f64) -> Result<f64, HwError> {
        if !volts.is_finite() {
            // As for a travel-limit breach: report the cause.
            self.halt_motor().ok();
            return Err(HwError::InvalidCommand {
                what: "voltage",
                channel: Some(self.calibration.pwm_channel),
                value: volts,
                limit: self.calibration.volts_full_scale,
            });
        }
        let duty = self.duty(volts);
        self.card.set_pwm(self.calibration.pwm_channel, duty)?;
        Ok(f64::from(duty) / f64::from(MAX_DUTY) * self.calibration.volts_full_scale)
    }

    fn halt_motor(&mut self) -> Result<(), HwError> {
        self.card.set_pwm(self.calibration.pwm_channel, 0)
    }
}

impl<P: EppPort> Rig<1, 4> for MassSpringRig<P> {
    #[inline]
    fn read(&mut self) -> Result<SVector<f64, 4>, HwError> {
        self.read_state()
    }

    #[inline]
    fn apply(&mut self, u: &SVector<f64, 1>) -> Result<SVector<f64, 1>, HwError> {
        Ok(vector![self.apply_voltage(u[0])?])
    }

    fn halt(&mut self) -> Result<(), HwError> {
        self.halt_motor()
    }

    fn period(&self) -> f64 {
        self.period
    }

    fn schema(&self) -> Schema {
        super::schema()
    }

    fn kick_watchdog(&mut self) -> Result<(), HwError> {
        self.card.kick_watchdog()
    }

    fn restart(&mut self) {
        self.previous = None;
    }
}

impl<P: EppPort> Drop for MassSpringRig<P> {
    fn drop(&mut self) {
        // Best effort: a failing port cannot be reported from a destructor,
        // and the card's watchdog zeroes the PWM anyway.
        self.halt_motor().ok();
    }
}
