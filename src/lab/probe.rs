//! The bring-up probe on the lab's rig: a simulated operator whose hands
//! move the simulated carts, and the calibration a probe report implies.

use nalgebra::SVector;

use super::Calibration;
use crate::hw::probe::{Hands, Operator, ProbeReport};
use crate::hw::testing::RecordingPort;
use crate::hw::{SimulatedCard, VirtualClock};
use crate::model::Dynamics;

/// The longest step of simulated time between two moves of the hand, s.
const HAND_STEP: f64 = 0.005;

/// A simulated person at the simulated rig, for
/// [`hw::probe::Probe`](crate::hw::probe::Probe): answers its questions from
/// a list, moves the carts of a [`SimulatedCard`] with the lab's four states
/// `[x1, v1, x2, v2]` as asked (a sine of `amplitude` at `frequency` for
/// [`Hands::Move`], `amplitude` away from the wall for [`Hands::Away`], the
/// other cart held at rest), and lets time pass on the shared
/// [`VirtualClock`]. It also works through a
/// [`RecordingPort`], so a test can see every cycle the probe made.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::probe::Hands;
/// use ctrlab::hw::{Clock, VirtualClock};
/// use ctrlab::lab::{SimulatedOperator, SimulatedRig};
///
/// let clock = VirtualClock::new();
/// let mut card = SimulatedRig::default().card(&Clock::Virtual(clock.clone()))?;
/// let mut hand = SimulatedOperator::new(clock.clone(), [true]);
/// hand.hands(Hands::Away(2));
/// hand.wait(&mut card, 0.1);
/// assert_eq!(clock.now(), 0.1);
/// assert!((card.true_state()[2] - 0.02).abs() < 1e-3);
/// assert!(hand.confirm("ready?"));
/// assert!(!hand.confirm("and again?")); // answers run out: no
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug, Clone)]
pub struct SimulatedOperator {
    clock: VirtualClock,
    answers: std::collections::VecDeque<bool>,
    hands: Hands,
    hand_time: f64,
    /// How far the hand moves a cart from rest, m.
    pub amplitude: f64,
    /// How fast it moves a cart back and forth, Hz.
    pub frequency: f64,
    /// Everything the probe said and asked, in order.
    pub transcript: Vec<String>,
}

impl SimulatedOperator {
    /// An operator on `clock` answering the probe's questions with
    /// `answers` in order (then "no"), moving the carts 20 mm at 0.7 Hz.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::VirtualClock, lab::SimulatedOperator};
    /// let hand = SimulatedOperator::new(VirtualClock::new(), [true, false]);
    /// assert_eq!(hand.amplitude, 0.02);
    /// ```
    pub fn new(clock: VirtualClock, answers: impl IntoIterator<Item = bool>) -> Self {
        Self {
            clock,
            answers: answers.into_iter().collect(),
            hands: Hands::Off,
            hand_time: 0.0,
            amplitude: 0.02,
            frequency: 0.7,
            transcript: Vec::new(),
        }
    }

    /// Where the hand puts the carts now, if it holds them.
    fn carts(&self) -> Option<[f64; 2]> {
        let place = |axis: usize, x: f64| {
            let mut carts = [0.0; 2];
            if let Some(c) = carts.get_mut(axis.wrapping_sub(1)) {
                *c = x;
            }
            carts
        };
        match self.hands {
            Hands::Off => None,
            Hands::Move(axis) => Some(place(
                axis,
                self.amplitude * (std::f64::consts::TAU * self.frequency * self.hand_time).sin(),
            )),
            Hands::Away(axis) => Some(place(axis, self.amplitude)),
        }
    }
}

impl SimulatedOperator {
    /// Records `message` in the [`transcript`](Self::transcript).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::VirtualClock, lab::SimulatedOperator};
    /// let mut hand = SimulatedOperator::new(VirtualClock::new(), []);
    /// hand.tell("Encoder 1 counts.");
    /// assert_eq!(hand.transcript, ["Encoder 1 counts."]);
    /// ```
    pub fn tell(&mut self, message: &str) {
        self.transcript.push(message.to_owned());
    }

    /// The next answer in the list (then "no"), recorded with `question`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::VirtualClock, lab::SimulatedOperator};
    /// let mut hand = SimulatedOperator::new(VirtualClock::new(), [true]);
    /// assert!(hand.confirm("Carts at rest?"));
    /// assert!(!hand.confirm("Again?")); // the list is used up: "no"
    /// assert_eq!(hand.transcript, ["Carts at rest? yes", "Again? no"]);
    /// ```
    pub fn confirm(&mut self, question: &str) -> bool {
        let answer = self.answers.pop_front().unwrap_or(false);
        self.transcript
            .push(format!("{question} {}", if answer { "yes" } else { "no" }));
        answer
    }

    /// Puts the hands as asked, restarting the back-and-forth motion.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, VirtualClock, probe::Hands};
    /// use ctrlab::lab::{SimulatedOperator, SimulatedRig};
    /// let clock = VirtualClock::new();
    /// let mut card = SimulatedRig::default().card(&Clock::Virtual(clock.clone()))?;
    /// let mut hand = SimulatedOperator::new(clock, []);
    /// hand.hands(Hands::Away(1));
    /// hand.wait(&mut card, 0.05);
    /// // Cart 1 held `amplitude` (20 mm) from the wall, cart 2 at rest.
    /// assert!((card.true_state()[0] - hand.amplitude).abs() < 1e-3);
    /// assert_eq!(hand.transcript, ["(hands: Away(1))"]);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn hands(&mut self, hands: Hands) {
        self.transcript.push(format!("(hands: {hands:?})"));
        self.hands = hands;
        self.hand_time = 0.0;
    }

    /// Advances the clock by `seconds` (clamped to 0–3600 s) in steps of
    /// at most 5 ms, placing the held carts (at rest) before each. A card
    /// error (a plant that diverged) is left for the probe's next register
    /// access to report.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, VirtualClock};
    /// use ctrlab::lab::{SimulatedOperator, SimulatedRig};
    /// let clock = VirtualClock::new();
    /// let mut card = SimulatedRig::default().card(&Clock::Virtual(clock.clone()))?;
    /// let mut hand = SimulatedOperator::new(clock.clone(), []);
    /// hand.wait(&mut card, 0.25);
    /// assert_eq!(clock.now(), 0.25); // s of virtual time, no real waiting
    /// hand.wait(&mut card, -1.0); // clamped to 0 s
    /// assert_eq!(clock.now(), 0.25);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn wait<D: Dynamics<4, 1>>(&mut self, card: &mut SimulatedCard<D, 4>, seconds: f64) {
        let seconds = if seconds.is_finite() {
            seconds.clamp(0.0, 3600.0)
        } else {
            0.0
        };
        let steps = (seconds / HAND_STEP).ceil() as usize;
        for _ in 0..steps {
            let dt = seconds / steps as f64;
            if let Some([x1, x2]) = self.carts() {
                // Sticky: the card reports the same error on its next access.
                let _ = card.set_true_state(SVector::from([x1, 0.0, x2, 0.0]));
            }
            self.hand_time += dt;
            // `dt` is finite and ≤ 5 ms; only the clock's end of time refuses.
            let _ = self.clock.advance(dt);
        }
    }
}

impl<D: Dynamics<4, 1>> Operator<SimulatedCard<D, 4>> for SimulatedOperator {
    fn tell(&mut self, message: &str) {
        SimulatedOperator::tell(self, message);
    }
    fn confirm(&mut self, question: &str) -> bool {
        SimulatedOperator::confirm(self, question)
    }
    fn hands(&mut self, hands: Hands) {
        SimulatedOperator::hands(self, hands);
    }
    fn wait(&mut self, port: &mut SimulatedCard<D, 4>, seconds: f64) {
        SimulatedOperator::wait(self, port, seconds);
    }
}

/// Through a [`RecordingPort`], so a test sees every cycle the probe made.
impl<D: Dynamics<4, 1>> Operator<RecordingPort<SimulatedCard<D, 4>>> for SimulatedOperator {
    fn tell(&mut self, message: &str) {
        SimulatedOperator::tell(self, message);
    }
    fn confirm(&mut self, question: &str) -> bool {
        SimulatedOperator::confirm(self, question)
    }
    fn hands(&mut self, hands: Hands) {
        SimulatedOperator::hands(self, hands);
    }
    fn wait(&mut self, port: &mut RecordingPort<SimulatedCard<D, 4>>, seconds: f64) {
        SimulatedOperator::wait(self, port.inner_mut(), seconds);
    }
}

impl Calibration {
    /// The calibration a [probe](crate::hw::probe::Probe) found: card ID,
    /// encoder channels and signs, PWM channel and watchdog from `report`;
    /// everything the probe cannot measure (metres per count, volts full
    /// scale, travel limits, plausibility limits) from `base`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::ProbeReport;
    /// use ctrlab::hw::RegisterMap;
    /// use ctrlab::lab::Calibration;
    /// let report = ProbeReport {
    ///     map: RegisterMap::default(),
    ///     card_id: 0x3c,
    ///     encoder_channels: [1, 0],
    ///     signs: [1.0, -1.0],
    ///     pwm_channel: 0,
    ///     watchdog_timeout: Some(0.05),
    ///     notes: Vec::new(),
    /// };
    /// let cal = Calibration::from_probe(&report, &Calibration::default());
    /// assert_eq!((cal.card_id, cal.encoder_channels, cal.sign), (0x3c, [1, 0], [1.0, -1.0]));
    /// assert_eq!(cal.metres_per_count, Calibration::default().metres_per_count);
    /// ```
    pub fn from_probe(report: &ProbeReport, base: &Calibration) -> Calibration {
        Calibration {
            sign: report.signs,
            pwm_channel: report.pwm_channel,
            encoder_channels: report.encoder_channels,
            card_id: report.card_id,
            watchdog_timeout: report.watchdog_timeout,
            ..*base
        }
    }
}
