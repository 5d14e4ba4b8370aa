//! Feedback taps of the maximum-length PRBS generator, one row per register
//! order n = 2 ..= 30.
//!
//! # Convention
//!
//! The taps are lags, written as MATLAB `idinput` writes its `ind` vector:
//! the generator remembers the last n values `u[k−1], …, u[k−n]` (each ±1)
//! and computes the next one as the product of the tapped ones,
//! `u[k] = Π_{t ∈ taps} u[k − t]`. With −1 as bit 1 and +1 as bit 0 the
//! product is the exclusive-or of the tapped bits, i.e. a Fibonacci linear
//! feedback shift register whose characteristic polynomial is
//! xⁿ + Σ_{t ∈ taps, t < n} x^{n−t} + 1 over GF(2). The sequence has the
//! maximal period 2ⁿ − 1 exactly when that polynomial is primitive; since a
//! polynomial is primitive iff its reciprocal is, a lag set and its mirror
//! image (t → n − t) are both maximal or both not, which is why tables that
//! number the register the other way round are still usable as lag sets.
//!
//! # Sources
//!
//! * Orders 3–18: MATLAB System Identification Toolbox, `idinput.m`
//!   (L. Ljung, 3‑3‑95; Copyright 1986–2003 The MathWorks; `$Revision:
//!   1.13.2.2 $ $Date: 2004/04/10$`), the `ind` vectors of its `'prbs'`
//!   branch, taken as they are. With them and a register started at all −1
//!   the generator reproduces that `idinput` sample for sample (for order 9:
//!   `---------++++----+---++++-+--++-…`). Later MATLAB releases moved the
//!   generator into `controllib.internal.util.genPRBS`, whose table could not
//!   be consulted; if it differs for some order, output for that order differs
//!   from those releases.
//! * Orders 19–30 (beyond that `idinput`): P. Alfke, *Efficient Shift
//!   Registers, LFSR Counters, and Long Pseudo-Random Sequence Generators*,
//!   Xilinx application note XAPP 052, v1.1, July 7, 1996, Table 3 ("taps for
//!   maximum-length LFSR counters"), bits numbered 1 … n as lags.
//! * Order 2: x² + x + 1 is the only primitive polynomial of degree 2, so the
//!   taps are necessarily {1, 2} (neither table lists order 2).
//!
//! Every row is checked by the tests of [`super::prbs`]: the register returns
//! to its start after exactly 2ⁿ − 1 steps and not after any proper divisor
//! of 2ⁿ − 1 (by exponentiation of the transition matrix over GF(2)), and for
//! orders up to 22 also by walking the whole period.

/// Where a row of [`TABLE`] comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TapSource {
    /// MATLAB `idinput.m`, revision 1.13.2.2 (2004), orders 3–18.
    Idinput,
    /// Xilinx XAPP 052 (Alfke, 1996), Table 3.
    Xapp052,
    /// The only primitive polynomial of degree 2, x² + x + 1.
    OnlyPrimitive,
}

impl TapSource {
    /// A short citation, as used in the node's documentation table.
    pub fn cite(&self) -> &'static str {
        match self {
            TapSource::Idinput => "MATLAB idinput",
            TapSource::Xapp052 => "Xilinx XAPP052",
            TapSource::OnlyPrimitive => "x²+x+1 (unique)",
        }
    }
}

/// The feedback taps of one register order.
#[derive(Debug, Clone, Copy)]
pub struct Taps {
    /// Register order n: the period is 2ⁿ − 1.
    pub order: u32,
    /// Lags t (1 ..= n, ascending, the last one n) whose product gives the
    /// next value: `u[k] = Π u[k − t]`.
    pub lags: &'static [u32],
    /// Where this row comes from.
    pub source: TapSource,
}

impl Taps {
    /// The taps as a bit mask over the register (bit t − 1 for lag t), for a
    /// register that holds `u[k−1]` in bit 0 and `u[k−n]` in bit n − 1.
    pub fn mask(&self) -> u32 {
        self.lags.iter().fold(0, |m, &t| m | 1 << (t - 1))
    }
}

/// Smallest supported order.
pub const MIN_ORDER: u32 = 2;
/// Largest supported order.
pub const MAX_ORDER: u32 = 30;

const fn row(order: u32, lags: &'static [u32], source: TapSource) -> Taps {
    Taps { order, lags, source }
}

use TapSource::{Idinput, OnlyPrimitive, Xapp052};

/// The table, orders 2 ..= 30 in order.
pub static TABLE: [Taps; 29] = [
    row(2, &[1, 2], OnlyPrimitive),
    row(3, &[1, 3], Idinput),
    row(4, &[1, 4], Idinput),
    row(5, &[2, 5], Idinput),
    row(6, &[1, 6], Idinput),
    row(7, &[1, 7], Idinput),
    row(8, &[1, 2, 7, 8], Idinput),
    row(9, &[4, 9], Idinput),
    row(10, &[3, 10], Idinput),
    row(11, &[9, 11], Idinput),
    row(12, &[6, 8, 11, 12], Idinput),
    row(13, &[9, 10, 12, 13], Idinput),
    row(14, &[4, 8, 13, 14], Idinput),
    row(15, &[14, 15], Idinput),
    row(16, &[4, 13, 15, 16], Idinput),
    row(17, &[14, 17], Idinput),
    row(18, &[11, 18], Idinput),
    row(19, &[1, 2, 6, 19], Xapp052),
    row(20, &[17, 20], Xapp052),
    row(21, &[19, 21], Xapp052),
    row(22, &[21, 22], Xapp052),
    row(23, &[18, 23], Xapp052),
    row(24, &[17, 22, 23, 24], Xapp052),
    row(25, &[22, 25], Xapp052),
    row(26, &[1, 2, 6, 26], Xapp052),
    row(27, &[1, 2, 5, 27], Xapp052),
    row(28, &[25, 28], Xapp052),
    row(29, &[27, 29], Xapp052),
    row(30, &[1, 4, 6, 30], Xapp052),
];

/// The taps of one order, or `None` outside [`MIN_ORDER`] ..= [`MAX_ORDER`].
pub fn taps(order: u32) -> Option<&'static Taps> {
    TABLE.iter().find(|t| t.order == order)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_complete_and_well_formed() {
        for (i, t) in TABLE.iter().enumerate() {
            assert_eq!(t.order, MIN_ORDER + i as u32);
            assert!(t.lags.windows(2).all(|w| w[0] < w[1]), "order {}: lags not ascending", t.order);
            assert_eq!(*t.lags.last().unwrap(), t.order, "order {}: the last lag must be n", t.order);
            assert!(t.lags.len() % 2 == 0, "order {}: an odd number of taps cannot be maximal", t.order);
            // The generator XORs exactly four shifted copies (two cancelling for two taps).
            assert!(t.lags.len() == 2 || t.lags.len() == 4, "order {}: the generator takes two or four taps", t.order);
            assert_eq!(t.mask().count_ones() as usize, t.lags.len());
        }
        assert_eq!(taps(9).unwrap().lags, &[4, 9]);
        assert!(taps(1).is_none() && taps(31).is_none());
    }
}
