//! Calendar dates and decimal years (proleptic Gregorian calendar, UTC).

use crate::error::{CoreError, Result};

/// A calendar date.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Date {
    /// Year, e.g. 2025.
    pub year: i32,
    /// Month 1–12.
    pub month: u32,
    /// Day of month 1–31.
    pub day: u32,
}

fn is_leap(y: i32) -> bool {
    (y % 4 == 0 && y % 100 != 0) || y % 400 == 0
}

fn days_in_month(y: i32, m: u32) -> u32 {
    match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if is_leap(y) => 29,
        _ => 28,
    }
}

impl Date {
    /// A validated date.
    pub fn new(year: i32, month: u32, day: u32) -> Result<Self> {
        if !(1..=12).contains(&month) {
            return Err(CoreError::InvalidArgument {
                name: "month",
                reason: format!("{month} is not in 1–12"),
            });
        }
        if day == 0 || day > days_in_month(year, month) {
            return Err(CoreError::InvalidArgument {
                name: "day",
                reason: format!("{year:04}-{month:02} has no day {day}"),
            });
        }
        Ok(Self { year, month, day })
    }

    /// Parse `YYYY-MM-DD`.
    pub fn parse(s: &str) -> Result<Self> {
        let bad = || CoreError::Parse {
            what: "date",
            reason: format!("`{s}` is not YYYY-MM-DD"),
        };
        let mut it = s.trim().split('-');
        let y: i32 = it.next().ok_or_else(bad)?.parse().map_err(|_| bad())?;
        let m: u32 = it.next().ok_or_else(bad)?.parse().map_err(|_| bad())?;
        let d: u32 = it.next().ok_or_else(bad)?.parse().map_err(|_| bad())?;
        if it.next().is_some() {
            return Err(bad());
        }
        Self::new(y, m, d)
    }

    /// Day of the year, 1-based.
    pub fn day_of_year(&self) -> u32 {
        (1..self.month)
            .map(|m| days_in_month(self.year, m))
            .sum::<u32>()
            + self.day
    }

    /// Decimal year at 00:00 UTC of this date: `year + (doy − 1)/days_in_year`
    /// (the convention of ppigrf and of the IGRF reference software).
    pub fn decimal_year(&self) -> f64 {
        let n = if is_leap(self.year) { 366.0 } else { 365.0 };
        self.year as f64 + (self.day_of_year() as f64 - 1.0) / n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_years() {
        assert_eq!(Date::parse("2020-01-01").unwrap().decimal_year(), 2020.0);
        let d = Date::parse("2021-07-02").unwrap();
        assert!((d.decimal_year() - (2021.0 + 182.0 / 365.0)).abs() < 1e-12);
        assert!(Date::parse("2021-02-29").is_err());
        assert!(Date::parse("2021-13-01").is_err());
        assert!(Date::parse("yesterday").is_err());
    }
}
