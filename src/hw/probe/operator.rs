//! The person at the rig ([`Operator`]) and what their hands do ([`Hands`]).

/// What the user's hands are doing, as the probe asks.
///
/// # Examples
///
/// The simulated hand records what the map check asks of it:
///
/// ```
/// use ctrlab::hw::probe::{Probe, ProbeOptions};
/// use ctrlab::hw::{Clock, VirtualClock};
/// use ctrlab::lab::{SimulatedOperator, SimulatedRig};
///
/// let (rig, clock) = (SimulatedRig::default(), VirtualClock::new());
/// let card = rig.card(&Clock::Virtual(clock.clone()))?;
/// let options = ProbeOptions { map: rig.card.map, ..Default::default() };
/// let mut probe = Probe::new(card, SimulatedOperator::new(clock, [true]), options)?;
/// probe.check_id()?;
/// probe.check_encoders()?;
/// let asked = &probe.operator().transcript;
/// // Each cart moved by hand, then held away from the wall.
/// for hands in ["Move(1)", "Move(2)", "Away(1)", "Away(2)"] {
///     assert!(asked.contains(&format!("(hands: {hands})")), "{hands}");
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hands {
    /// Hands off the carts; let them come to rest.
    Off,
    /// Moving this axis (1 or 2: cart 1 or cart 2) back and forth by hand
    /// over a few centimetres, holding the other axis still.
    Move(usize),
    /// Holding this axis a few centimetres away from the wall (its rest
    /// position), the other axis still.
    Away(usize),
}

/// The person at the rig, as the probe sees them: someone to tell what
/// happens, to ask, and to move the carts; and the passing of time.
///
/// The `probe` example implements it on a console; a simulated operator
/// moves the simulated carts in [`wait`](Self::wait).
///
/// # Examples
///
/// An operator who says no stops the probe before it writes anything:
///
/// ```
/// use ctrlab::hw::probe::{Hands, Operator, Probe, ProbeError, ProbeOptions};
/// use ctrlab::hw::testing::{RecordingPort, RegisterFile};
/// use ctrlab::hw::CycleKind;
///
/// struct Careful;
/// impl<P> Operator<P> for Careful {
///     fn tell(&mut self, _message: &str) {}
///     fn confirm(&mut self, _question: &str) -> bool { false }
///     fn hands(&mut self, _hands: Hands) {}
///     fn wait(&mut self, _port: &mut P, _seconds: f64) {}
/// }
///
/// let mut card = RegisterFile::new();
/// card.set(0x00, 0xa5); // an ID register, nothing else
/// let options = ProbeOptions { scan: true, ..Default::default() };
/// let mut probe = Probe::new(RecordingPort::new(card), Careful, options)?;
/// probe.scan()?;
/// assert!(matches!(probe.find_encoders(), Err(ProbeError::Declined { .. })));
/// assert!(probe.port().log().iter().all(|c| c.kind() != CycleKind::DataWrite));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait Operator<P> {
    /// Shows a message: what the probe is about to do, or what it found.
    fn tell(&mut self, message: &str);

    /// Asks a yes/no question; `true` only for a clear yes.
    fn confirm(&mut self, question: &str) -> bool;

    /// Asks the user to put their hands as `hands` says, and returns when
    /// they are ready.
    fn hands(&mut self, hands: Hands);

    /// Lets `seconds` pass (s, ≥ 0). The port is passed so that a
    /// simulated world can move its carts meanwhile; a real operator just
    /// sleeps.
    fn wait(&mut self, port: &mut P, seconds: f64);
}

impl<P, O: Operator<P> + ?Sized> Operator<P> for &mut O {
    fn tell(&mut self, message: &str) {
        (**self).tell(message);
    }
    fn confirm(&mut self, question: &str) -> bool {
        (**self).confirm(question)
    }
    fn hands(&mut self, hands: Hands) {
        (**self).hands(hands);
    }
    fn wait(&mut self, port: &mut P, seconds: f64) {
        (**self).wait(port, seconds);
    }
}
