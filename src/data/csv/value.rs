//! One field's number: a decimal point, or a decimal comma in files
//! separated by `;` or a tab.

/// Why a field is not a number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum BadValue {
    /// Empty.
    Empty,
    /// Not a number at all.
    NotANumber,
    /// A decimal comma and a point, or two commas: a thousands separator.
    Thousands,
}

impl BadValue {
    /// The reason of a [`CsvError::Line`](super::CsvError::Line) for field `text`
    /// of column `column`.
    pub(super) fn describe(self, column: &str, text: &str, decimal_comma: bool) -> String {
        match self {
            BadValue::Empty => format!("column {column} is empty"),
            BadValue::NotANumber if !decimal_comma && text.contains(',') => format!(
                "column {column}: `{text}` is not a number (a decimal comma is read only \
                 in files separated by `;` or tabs)"
            ),
            BadValue::NotANumber => format!("column {column}: `{text}` is not a number"),
            BadValue::Thousands => format!(
                "column {column}: `{text}` is not a number: it looks like a thousands \
                 separator; write numbers without one (one decimal comma or point)"
            ),
        }
    }
}

/// Parses a trimmed field. With `decimal_comma`, one `,` is the decimal
/// separator (`0,002`); a comma with a point or a second comma
/// (`1.234,5`, `1,234,5`) is refused, since it can only be a thousands
/// separator. `scratch` holds the rewritten text, so reading allocates once
/// per file, not per value.
pub(super) fn parse(
    text: &str,
    decimal_comma: bool,
    scratch: &mut String,
) -> Result<f64, BadValue> {
    if decimal_comma && let Some(at) = text.bytes().position(|b| b == b',') {
        let (head, tail) = (&text[..at], &text[at + 1..]);
        if head.contains('.') || tail.contains([',', '.']) {
            return Err(BadValue::Thousands);
        }
        scratch.clear();
        scratch.push_str(head);
        scratch.push('.');
        scratch.push_str(tail);
        return scratch.parse().map_err(|_| BadValue::NotANumber);
    }
    text.parse().map_err(|_| {
        if text.is_empty() {
            BadValue::Empty
        } else {
            BadValue::NotANumber
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_commas_only_where_asked() {
        let mut s = String::new();
        assert_eq!(parse("0,002", true, &mut s), Ok(0.002));
        assert_eq!(parse("-1,5e-3", true, &mut s), Ok(-1.5e-3));
        assert_eq!(parse("0.002", true, &mut s), Ok(0.002));
        assert_eq!(parse("12", true, &mut s), Ok(12.0));
        assert_eq!(parse("0,002", false, &mut s), Err(BadValue::NotANumber));
        assert_eq!(parse("1.234,5", true, &mut s), Err(BadValue::Thousands));
        assert_eq!(parse("1,234.5", true, &mut s), Err(BadValue::Thousands));
        assert_eq!(parse("1,234,5", true, &mut s), Err(BadValue::Thousands));
        assert_eq!(parse(",", true, &mut s), Err(BadValue::NotANumber));
        assert_eq!(parse("", true, &mut s), Err(BadValue::Empty));
        assert_eq!(parse("x", false, &mut s), Err(BadValue::NotANumber));
        // Long, and not ASCII.
        let long = format!("0,{}1", "0".repeat(80));
        assert_eq!(parse(&long, true, &mut s), Ok(1e-81));
        assert_eq!(
            parse(&format!("{long}x"), true, &mut s),
            Err(BadValue::NotANumber)
        );
        assert_eq!(parse("é,5", true, &mut s), Err(BadValue::NotANumber));
        // Any length: as with a point.
        let digits = "1234567890".repeat(5);
        for n in 0..=40 {
            let comma = format!("-{},{}e-3", &digits[..n], &digits[n..40]);
            let point = comma.replace(',', ".");
            let want = point.parse::<f64>().unwrap();
            assert_eq!(
                parse(&comma, true, &mut s).map(f64::to_bits),
                Ok(want.to_bits()),
                "{comma}"
            );
        }
        let why = BadValue::Thousands.describe("x1", "1.234,5", true);
        assert!(
            why.contains("`1.234,5`") && why.contains("thousands"),
            "{why}"
        );
        let why = BadValue::NotANumber.describe("x1", "0,5", false);
        assert!(why.contains("`0,5`") && why.contains(';'), "{why}");
    }
}
