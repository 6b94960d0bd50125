//! The sample fraction f of the real-time frame: below one sample per pixel, each frame traces
//! one pixel in 1/f (Dundr et al., §5). Spelled as users write it: "1", "1/2", ... "1/128".

use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

/// The largest period 1/f (a pixel is traced once every this many frames).
pub const MAX_SAMPLE_PERIOD: u32 = 128;

/// f = 1 / period, period a power of two up to [`MAX_SAMPLE_PERIOD`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct SampleFraction {
    period: u32,
}

impl Default for SampleFraction {
    fn default() -> Self {
        SampleFraction::ONE
    }
}

impl SampleFraction {
    pub const ONE: SampleFraction = SampleFraction { period: 1 };

    /// 1 / `period`; an error unless the period is a power of two in 1..=128.
    pub fn one_in(period: u32) -> Result<SampleFraction> {
        if !period.is_power_of_two() || period > MAX_SAMPLE_PERIOD {
            bail!(
                "a sample fraction is 1/N with N a power of two up to {MAX_SAMPLE_PERIOD}, not 1/{period}"
            );
        }
        Ok(SampleFraction { period })
    }

    /// Frames between two samples of one pixel (1 / f).
    pub fn period(self) -> u32 {
        self.period
    }

    /// Every fraction, in the order a menu lists them.
    pub fn all() -> impl Iterator<Item = SampleFraction> {
        (0..=MAX_SAMPLE_PERIOD.trailing_zeros()).map(|k| SampleFraction { period: 1 << k })
    }
}

impl std::fmt::Display for SampleFraction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.period {
            1 => write!(f, "1"),
            n => write!(f, "1/{n}"),
        }
    }
}

impl std::str::FromStr for SampleFraction {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<SampleFraction> {
        let t = s.trim();
        if t == "1" {
            return Ok(SampleFraction::ONE);
        }
        let Some(n) = t.strip_prefix("1/").and_then(|n| n.trim().parse::<u32>().ok()) else {
            bail!("sample fraction {s:?}: write 1 or 1/N (N = 2, 4, ... {MAX_SAMPLE_PERIOD})");
        };
        SampleFraction::one_in(n)
    }
}

impl TryFrom<String> for SampleFraction {
    type Error = anyhow::Error;
    fn try_from(s: String) -> Result<SampleFraction> {
        s.parse()
    }
}

impl From<SampleFraction> for String {
    fn from(f: SampleFraction) -> String {
        f.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_parse_and_print_as_written() {
        for f in SampleFraction::all() {
            assert_eq!(f.to_string().parse::<SampleFraction>().unwrap(), f);
        }
        assert_eq!("1/16".parse::<SampleFraction>().unwrap().period(), 16);
        for bad in ["1/3", "1/256", "1/0", "2", "0.5", "1/", "half"] {
            assert!(bad.parse::<SampleFraction>().is_err(), "{bad}");
        }
    }
}
