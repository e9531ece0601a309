//! `--scope`: the run drawn live in the terminal, as the lab's Simulink
//! scope shows it: the controlled cart's position against the setpoint, and
//! the drive.
//!
//! The 2 ms loop never waits on drawing: its controller is wrapped in a
//! [`Tap`] that hands each tick's sample to a wait-free single-producer
//! queue (`rtrb`); a full queue drops the sample (counted) instead of
//! blocking. A drawing thread empties the queue about 20 times a second,
//! draws with ratatui, and reads the keys: `q`, Esc or Ctrl-C (the terminal
//! is in raw mode, so Ctrl-C is a key, not a signal) request the loop's
//! stop, which halts the rig at its next tick. A terminal that goes away
//! (its window closed, its tmux killed) requests the stop too.

use std::cell::Cell;
use std::io;
use std::rc::Rc;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

use ctrlab::Controller;
use ctrlab::hw::StopSignal;
use ctrlab::lab::Cart;
use ctrlab::lab::tables::Experiment;
use ctrlab::nalgebra::SVector;
use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind, KeyModifiers};
use ratatui::layout::{Constraint, Layout};
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::text::Line;
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType};
use rtrb::{Consumer, Producer, RingBuffer};

/// Samples the queue holds: 2 s of the loop at 2 ms, far more than a
/// frame (50 ms) takes; only a drawing thread stalled for seconds drops.
const QUEUE: usize = 1000;

/// How often the scope redraws and polls the keys.
const FRAME: Duration = Duration::from_millis(50);

/// One tick as the scope draws it: time (s), the drive (V), the carts'
/// positions (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub t: f64,
    pub u: f64,
    pub x_mm: [f64; 2],
}

/// The sampling instant of the tick in progress, from the reference (the
/// loop evaluates it at the sampling instant, before the controller).
pub type Now = Rc<Cell<f64>>;

/// `inner`, passed through unchanged, handing each applied input with the
/// tick's measurement to the scope's queue without ever blocking.
pub struct Tap<C> {
    inner: C,
    producer: Producer<Sample>,
    now: Now,
    x_mm: [f64; 2],
    dropped: Arc<AtomicUsize>,
}

impl<C> Tap<C> {
    /// Wraps `inner`; `now` is set by the reference ([`timed`]).
    pub fn new(inner: C, producer: Producer<Sample>, now: Now) -> Self {
        Self {
            inner,
            producer,
            now,
            x_mm: [0.0; 2],
            dropped: Arc::new(AtomicUsize::new(0)),
        }
    }

    /// Samples dropped on a full queue, shared with the caller.
    pub fn dropped(&self) -> Arc<AtomicUsize> {
        Arc::clone(&self.dropped)
    }
}

impl<C: Controller<4, 1, 1>> Controller<4, 1, 1> for Tap<C> {
    fn update(&mut self, y: &SVector<f64, 4>, r: &SVector<f64, 1>) -> SVector<f64, 1> {
        self.x_mm = [y[0] * 1e3, y[2] * 1e3];
        self.inner.update(y, r)
    }

    fn applied(&mut self, u: &SVector<f64, 1>) {
        self.inner.applied(u);
        let sample = Sample {
            t: self.now.get(),
            u: u[0],
            x_mm: self.x_mm,
        };
        // Wait-free: a full queue drops the sample rather than the tick.
        if self.producer.push(sample).is_err() {
            self.dropped.fetch_add(1, Ordering::Relaxed);
        }
    }

    fn reset(&mut self) {
        self.inner.reset();
    }

    fn period(&self) -> Option<f64> {
        self.inner.period()
    }
}

/// `reference`, noting each sampling instant in `now` for the [`Tap`].
pub fn timed(
    mut reference: impl FnMut(f64) -> SVector<f64, 1>,
    now: Now,
) -> impl FnMut(f64) -> SVector<f64, 1> {
    move |t| {
        now.set(t);
        reference(t)
    }
}

/// The queue between the loop and the scope.
pub fn queue() -> (Producer<Sample>, Consumer<Sample>) {
    RingBuffer::new(QUEUE)
}

/// The drawing thread, until [`finish`](Self::finish).
pub struct Scope {
    done: Arc<AtomicBool>,
    thread: JoinHandle<io::Result<()>>,
}

/// What the scope draws beside the samples.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    pub experiment: Experiment,
    /// The drive's limit, V.
    pub volts_full_scale: f64,
    /// The controlled cart's travel limit, mm.
    pub travel_mm: f64,
}

impl Scope {
    /// Takes the terminal (raw mode, alternate screen) and draws the
    /// samples from `samples` until [`finish`](Self::finish); `q`, Esc and
    /// Ctrl-C request `stop`.
    ///
    /// # Errors
    ///
    /// The terminal cannot be taken (not a terminal): before the run, so
    /// nothing is driven without the scope asked for.
    pub fn start(samples: Consumer<Sample>, stop: StopSignal, frame: Frame) -> io::Result<Self> {
        let keys = Keys::open()?;
        let mut terminal = ratatui::try_init()?;
        let done = Arc::new(AtomicBool::new(false));
        let finished = Arc::clone(&done);
        let thread = std::thread::spawn(move || {
            let result = draw_until(&mut terminal, &keys, samples, &stop, &finished, frame);
            ratatui::try_restore()?;
            result
        });
        Ok(Self { done, thread })
    }

    /// Stops drawing (after one last frame) and gives the terminal back.
    pub fn finish(self) -> io::Result<()> {
        self.done.store(true, Ordering::Release);
        self.thread
            .join()
            .unwrap_or_else(|_| Err(io::Error::other("the scope's thread panicked")))
    }
}

/// What the terminal has for the scope after a wait.
enum Input {
    /// Nothing within the wait.
    Nothing,
    /// Bytes to read: maybe a key.
    Ready,
    /// Hung up: the terminal is gone (seen on Linux only).
    #[cfg_attr(not(target_os = "linux"), allow(dead_code))]
    Gone,
}

/// The terminal the keys come from (crossterm's: stdin when it is one,
/// else /dev/tty), on Linux watched for its hang-up before crossterm reads it:
/// crossterm's reader loops forever on a hung-up terminal (its reads of
/// 0 bytes are no end to it), which would leave the process spinning after
/// the run.
struct Keys {
    #[cfg(target_os = "linux")]
    tty: Option<std::fs::File>,
}

impl Keys {
    #[cfg(target_os = "linux")]
    fn open() -> io::Result<Self> {
        use std::io::IsTerminal;
        let tty = if io::stdin().is_terminal() {
            None
        } else {
            Some(std::fs::File::open("/dev/tty")?)
        };
        Ok(Self { tty })
    }

    /// Waits up to `timeout` for the terminal.
    #[cfg(target_os = "linux")]
    fn wait(&self, timeout: Duration) -> io::Result<Input> {
        use std::os::fd::AsRawFd;
        let fd = self.tty.as_ref().map_or(0, AsRawFd::as_raw_fd);
        let mut poll = libc::pollfd {
            fd,
            events: libc::POLLIN,
            revents: 0,
        };
        let ms = i32::try_from(timeout.as_millis()).unwrap_or(i32::MAX);
        // SAFETY: one pollfd, valid for the call; the fd is open (stdin, or
        // the file `self` holds).
        if unsafe { libc::poll(&mut poll, 1, ms) } < 0 {
            let e = io::Error::last_os_error();
            return match e.kind() {
                io::ErrorKind::Interrupted => Ok(Input::Nothing),
                _ => Err(e),
            };
        }
        Ok(
            if poll.revents & (libc::POLLHUP | libc::POLLERR | libc::POLLNVAL) != 0 {
                Input::Gone
            } else if poll.revents & libc::POLLIN != 0 {
                Input::Ready
            } else {
                Input::Nothing
            },
        )
    }

    // Elsewhere crossterm's own wait (macOS's poll(2) has not always
    // taken terminals, and this was tested on Linux only).
    #[cfg(not(target_os = "linux"))]
    fn open() -> io::Result<Self> {
        Ok(Self {})
    }

    #[cfg(not(target_os = "linux"))]
    fn wait(&self, timeout: Duration) -> io::Result<Input> {
        Ok(if event::poll(timeout)? {
            Input::Ready
        } else {
            Input::Nothing
        })
    }
}

fn draw_until(
    terminal: &mut ratatui::DefaultTerminal,
    keys: &Keys,
    mut samples: Consumer<Sample>,
    stop: &StopSignal,
    done: &AtomicBool,
    frame: Frame,
) -> io::Result<()> {
    let cart = frame.experiment.cart;
    let index = usize::from(cart == Cart::Two);
    let (mut position, mut drive) = (Vec::new(), Vec::new());
    loop {
        // Read `done` before emptying the queue: the loop has pushed its
        // last sample by then, so the last frame has them all.
        let last = done.load(Ordering::Acquire);
        while let Ok(s) = samples.pop() {
            position.push((s.t, s.x_mm[index]));
            drive.push((s.t, s.u));
        }
        terminal.draw(|f| render(f, &position, &drive, frame, stop.is_requested()))?;
        if last {
            return Ok(());
        }
        match keys.wait(FRAME)? {
            Input::Nothing => {}
            // Nobody can watch the run or stop it any more: stopped, as
            // the SIGHUP of a closed terminal stops it.
            Input::Gone => {
                stop.request();
                std::thread::sleep(FRAME);
            }
            Input::Ready => {
                while event::poll(Duration::ZERO)? {
                    if let Event::Key(key) = event::read()?
                        && key.kind == KeyEventKind::Press
                    {
                        let ctrl_c = key.code == KeyCode::Char('c')
                            && key.modifiers.contains(KeyModifiers::CONTROL);
                        if ctrl_c || matches!(key.code, KeyCode::Char('q') | KeyCode::Esc) {
                            stop.request();
                        }
                    }
                }
            }
        }
    }
}

fn render(
    f: &mut ratatui::Frame,
    position: &[(f64, f64)],
    drive: &[(f64, f64)],
    frame: Frame,
    stopping: bool,
) {
    let e = frame.experiment;
    let duration = e.duration;
    let [top, bottom] =
        Layout::vertical([Constraint::Percentage(65), Constraint::Percentage(35)]).areas(f.area());
    let setpoint = [(0.0, e.setpoint_mm), (duration, e.setpoint_mm)];
    let t_axis = || {
        Axis::default()
            .title("t (s)")
            .bounds([0.0, duration])
            .labels(["0".to_string(), format!("{duration}")])
    };
    let travel = frame.travel_mm;
    let title = format!(
        " cart {}, Kf = [{} {} {} {}], to {} mm  ({}) ",
        e.cart.number(),
        e.gains.kf[0],
        e.gains.kf[1],
        e.gains.kf[2],
        e.gains.kf[3],
        e.setpoint_mm,
        if stopping {
            "stopping: the rig halts"
        } else {
            "q, Esc or Ctrl-C stops the run"
        }
    );
    let x = Chart::new(vec![
        Dataset::default()
            .name("setpoint")
            .marker(Marker::Braille)
            .graph_type(GraphType::Line)
            .style(Style::default().fg(Color::DarkGray))
            .data(&setpoint),
        Dataset::default()
            .name(format!("x{} (mm)", e.cart.number()))
            .marker(Marker::Braille)
            .graph_type(GraphType::Line)
            .style(Style::default().fg(Color::Cyan))
            .data(position),
    ])
    .block(Block::bordered().title(Line::from(title)))
    .x_axis(t_axis())
    .y_axis(
        Axis::default()
            .title("mm")
            .bounds([-travel, travel])
            .labels([format!("{}", -travel), "0".into(), format!("{travel}")]),
    );
    let full = frame.volts_full_scale;
    let u = Chart::new(vec![
        Dataset::default()
            .name("u (V)")
            .marker(Marker::Braille)
            .graph_type(GraphType::Line)
            .style(Style::default().fg(Color::Yellow))
            .data(drive),
    ])
    .block(Block::bordered().title(" drive "))
    .x_axis(t_axis())
    .y_axis(Axis::default().title("V").bounds([-full, full]).labels([
        format!("{}", -full),
        "0".into(),
        format!("{full}"),
    ]));
    f.render_widget(x, top);
    f.render_widget(u, bottom);
}

#[cfg(test)]
mod tests {
    use super::*;
    use ctrlab::lab::LabGains;
    use ctrlab::nalgebra::vector;

    /// The tap changes nothing the loop sees, and a full queue costs
    /// samples, never a wait.
    #[test]
    fn the_tap_passes_through_and_drops_rather_than_blocks() {
        let law = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
            .state_feedback()
            .unwrap();
        let (producer, mut consumer) = RingBuffer::new(2);
        let now = Now::default();
        let mut tap = Tap::new(law, producer, Rc::clone(&now));
        let mut reference = timed(|_| vector![0.030], Rc::clone(&now));
        let mut plain = law;
        let y = vector![0.001, 0.0, 0.005, 0.01];
        for k in 0..5 {
            let r = reference(k as f64 * 0.002);
            let u = tap.update(&y, &r);
            assert_eq!(u, plain.update(&y, &r));
            tap.applied(&u);
        }
        assert_eq!(tap.dropped().load(Ordering::Relaxed), 3);
        let first = consumer.pop().unwrap();
        assert_eq!((first.t, first.x_mm), (0.0, [1.0, 5.0]));
        assert_eq!(consumer.pop().unwrap().t, 0.002);
        assert!(consumer.pop().is_err());
    }
}
