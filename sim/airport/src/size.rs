//! ICAO aerodrome reference code letters (Annex 14): an aircraft's from its wingspan, a taxiway's
//! and a stand's from the largest aircraft they take.

use std::fmt;

/// Code letter A (smallest) to F.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SizeClass {
    /// Wingspan under 15 m.
    A,
    /// 15 m to under 24 m (a Praetor 600: 21.5 m).
    B,
    /// 24 m to under 36 m (an A320: 35.8 m).
    C,
    /// 36 m to under 52 m.
    D,
    /// 52 m to under 65 m.
    E,
    /// 65 m to under 80 m.
    F,
}

impl SizeClass {
    const ALL: [Self; 6] = [Self::A, Self::B, Self::C, Self::D, Self::E, Self::F];
    const SPAN_BELOW_M: [f64; 6] = [15.0, 24.0, 36.0, 52.0, 65.0, 80.0];

    /// The code letter of an aircraft of this wingspan, `None` at 80 m and over (or not a span).
    #[must_use]
    pub fn for_wingspan(span_m: f64) -> Option<Self> {
        if span_m.is_nan() || span_m < 0.0 {
            return None;
        }
        Self::ALL
            .iter()
            .zip(Self::SPAN_BELOW_M)
            .find(|(_, below)| span_m < *below)
            .map(|(c, _)| *c)
    }

    /// The largest wingspan of the letter (exclusive, m).
    #[must_use]
    pub fn span_below_m(self) -> f64 {
        Self::SPAN_BELOW_M[self as usize]
    }

    /// `'A'` .. `'F'`.
    #[must_use]
    pub fn from_letter(letter: char) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.letter() == letter)
    }

    /// Its letter.
    #[must_use]
    pub fn letter(self) -> char {
        (b'A' + self as u8) as char
    }
}

impl fmt::Display for SizeClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.letter())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wingspans_give_the_annex_14_letters() {
        assert_eq!(SizeClass::for_wingspan(21.5), Some(SizeClass::B));
        assert_eq!(SizeClass::for_wingspan(35.8), Some(SizeClass::C));
        assert_eq!(SizeClass::for_wingspan(14.99), Some(SizeClass::A));
        assert_eq!(SizeClass::for_wingspan(15.0), Some(SizeClass::B));
        assert_eq!(SizeClass::for_wingspan(79.8), Some(SizeClass::F));
        assert_eq!(SizeClass::for_wingspan(80.0), None);
        assert_eq!(SizeClass::for_wingspan(f64::NAN), None);
        assert_eq!(
            SizeClass::from_letter('D').map(SizeClass::letter),
            Some('D')
        );
        assert_eq!(SizeClass::from_letter('G'), None);
    }
}
