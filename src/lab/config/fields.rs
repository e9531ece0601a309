//! The keys of a card file ([`FIELDS`]): what [`RigConfig::to_toml`](super::RigConfig::to_toml)
//! writes beside each, and which it writes in hex.

/// One key of the file: its dotted name, what it means (the comment
/// [`RigConfig::to_toml`] writes beside it), and whether its values are
/// addresses, bit masks or IDs, written in hex.
pub(super) struct Field {
    pub(super) key: &'static str,
    pub(super) comment: &'static str,
    pub(super) hex: bool,
}

const fn field(key: &'static str, comment: &'static str, hex: bool) -> Field {
    Field { key, comment, hex }
}

/// Every key of the file, in the order [`RigConfig::to_toml`] writes them.
const FIELDS: [Field; 28] = [
    field("map.id", "card ID register (read)", true),
    field(
        "map.control",
        "control register (write): the strobes below",
        true,
    ),
    field("map.latch_bit", "latches all four counters at once", true),
    field("map.clear_bit", "clears all four counters", true),
    field("map.watchdog_bit", "kicks the watchdog", true),
    field("map.pwm_low", "PWM channel 0-3: duty bits 0-7", true),
    field(
        "map.pwm_high",
        "duty bits 8-9, bit 7 direction; applies the duty",
        true,
    ),
    field(
        "map.encoder",
        "counter 0-3: 32 bits little-endian, 4 addresses each",
        true,
    ),
    field("calibration.metres_per_count", "m per encoder count", false),
    field(
        "calibration.sign",
        "+1: counting up moves the cart away from the wall",
        false,
    ),
    field(
        "calibration.volts_full_scale",
        "V at 100 % duty; commands saturate at ± this",
        false,
    ),
    field(
        "calibration.pwm_channel",
        "the motor's PWM channel (0-3)",
        false,
    ),
    field(
        "calibration.encoder_channels",
        "cart 1's and cart 2's encoder (0-3, distinct)",
        false,
    ),
    field(
        "calibration.travel_limits",
        "m, ± about where the counters were cleared",
        false,
    ),
    field(
        "calibration.card_id",
        "what the ID register must read (not 0x00 or 0xff)",
        true,
    ),
    field(
        "calibration.watchdog_timeout",
        "s, or \"none\" for a card without one",
        false,
    ),
    field(
        "calibration.no_watchdog_acknowledged",
        "true: drive a card without a watchdog anyway",
        false,
    ),
    field(
        "calibration.max_speed",
        "m/s: a faster count change is a bus fault",
        false,
    ),
    field(
        "calibration.stall_volts",
        "V of new drive that must move cart 2's encoder",
        false,
    ),
    field(
        "calibration.stall_time",
        "s cart 2 may take to answer it",
        false,
    ),
    field("calibration.stall_counts", "counts that answer it", false),
    field(
        "calibration.follow_time",
        "s cart 2's encoder may lag cart 1's in answering it",
        false,
    ),
    field(
        "calibration.max_saturation_time",
        "s the drive may stay at ± volts_full_scale",
        false,
    ),
    field(
        "port.data_dir",
        "PPDATADIR around each EPP read (default false)",
        false,
    ),
    field(
        "ident.signal",
        "identification input: square, prbs or multisine",
        false,
    ),
    field(
        "ident.volts",
        "V peak asked for (the largest the scaling chooses)",
        false,
    ),
    field("ident.half_period", "s, the square wave's", false),
    field(
        "ident.scale_to_travel",
        "probe runs first, amplitude within 60 % of the travel",
        false,
    ),
];

/// The [`FIELDS`] entry of `name` in `section`.
pub(super) fn lookup(section: &str, name: &str) -> Option<&'static Field> {
    FIELDS.iter().find(|f| {
        f.key
            .strip_prefix(section)
            .and_then(|rest| rest.strip_prefix('.'))
            == Some(name)
    })
}

/// Every decimal integer in `value` (a TOML integer or array of them)
/// written in hex.
pub(super) fn hex(value: &str) -> String {
    let mut out = String::with_capacity(value.len() * 2);
    let mut digits = String::new();
    for c in value.chars().chain(std::iter::once(' ')) {
        if c.is_ascii_digit() {
            digits.push(c);
            continue;
        }
        match digits.parse::<u8>() {
            Ok(n) => out.push_str(&format!("{n:#04x}")),
            Err(_) => out.push_str(&digits),
        }
        digits.clear();
        out.push(c);
    }
    out.pop(); // the sentinel
    out
}
