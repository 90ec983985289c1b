//! How many of an `i128` sum's four `u32` words a part stores: a summed
//! channel keeps its words `w0` … `w{m−1}` for the least m in which every
//! pixel's sum fits as a signed integer; a missing word is the sign
//! extension of the word below it. Most passes' sums fit in one or two
//! words, so a part's high words are rarely written, copied or compressed
//! (docs/farm.md, "Parts").

/// The least number of words (1–4) that hold `v` as a signed integer.
pub(super) fn words_needed(v: i128) -> usize {
    (1..4).find(|&m| fits(v, 32 * m as u32)).unwrap_or(4)
}

/// Whether `v` is the sign extension of its low `bits` bits.
fn fits(v: i128, bits: u32) -> bool {
    let shift = 128 - bits;
    (v << shift) >> shift == v
}

/// The word above a missing one: all ones below a negative top word,
/// zero otherwise.
pub(super) fn extension_of(below: u32) -> u32 {
    ((below as i32) >> 31) as u32
}

/// The four words of a sum from the stored ones (`w0` first; at least
/// one): the missing high words extend the highest stored one.
pub(super) fn widened(stored: &[u32]) -> [u32; 4] {
    let mut w = [0u32; 4];
    for j in 0..4 {
        w[j] = match stored.get(j) {
            Some(&v) => v,
            None => extension_of(w[j - 1]),
        };
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::accumulate::{from_words, to_words};

    /// Each width's edges, both signs: the mistake is an off-by-one bit
    /// (2^31 kept in one word, or −2^31 − 1) or a high word extended with
    /// zeros below a negative word.
    #[test]
    fn the_stored_words_give_back_every_sum() {
        let mut values = vec![0i128, 1, -1, i128::MAX, i128::MIN];
        for bits in [32, 64, 96] {
            let edge = 1i128 << (bits - 1);
            values.extend([edge - 1, edge, -edge, -edge - 1]);
        }
        for v in values {
            let m = words_needed(v);
            let stored = &to_words(v)[..m];
            assert_eq!(from_words(widened(stored)), v, "{v} in {m} words");
            if m > 1 {
                let fewer = &to_words(v)[..m - 1];
                assert_ne!(from_words(widened(fewer)), v, "{v} fits {} words", m - 1);
            }
        }
        assert_eq!(words_needed((1 << 31) - 1), 1);
        assert_eq!(words_needed(1 << 31), 2);
        assert_eq!(words_needed(-(1 << 31)), 1);
        assert_eq!(words_needed(-(1 << 31) - 1), 2);
    }
}
