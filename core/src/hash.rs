//! Fast hashers for keys we make ourselves: vertex and face indices, index pairs, overlay labels,
//! exact coordinate bits. The std SipHash resists hash flooding, which buys nothing for such keys
//! and costs most of the time of the stages that hash millions of them (the morph overlay, the
//! fit's edge sets, the STL weld).

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// Multiplicative hash for small integer keys (indices, pairs of indices, small enums of them).
/// Every integer is folded in as one `u64` word; the final xor-shift brings the well-mixed high
/// bits down to the low bits that pick the bucket.
#[derive(Default)]
pub struct IntHasher(u64);

impl Hasher for IntHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u32(&mut self, i: u32) {
        self.write_u64(i as u64);
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(26) ^ i).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
    // Enum discriminants and `usize` keys arrive here: one word, not eight bytes.
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    fn finish(&self) -> u64 {
        self.0 ^ (self.0 >> 29)
    }
}

pub type IntMap<K, V> = HashMap<K, V, BuildHasherDefault<IntHasher>>;
pub type IntSet<K> = HashSet<K, BuildHasherDefault<IntHasher>>;

/// Hasher for exact coordinate bit patterns. Values are combined with a multiply and finished
/// with the splitmix64 mixer, so coordinates whose low mantissa bits are all zero (0.5, 1.25, …:
/// common in hand-made files) still spread over the buckets, which the plain [`IntHasher`]
/// finish does not guarantee.
#[derive(Default)]
pub struct BitsHasher(u64);

impl Hasher for BitsHasher {
    fn finish(&self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(23) ^ v).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::{BuildHasher, Hash};

    fn hash_of<H: Hasher + Default>(key: impl Hash) -> u64 {
        BuildHasherDefault::<H>::default().hash_one(key)
    }

    /// Keys that differ only in one small index must not collide (the maps' whole point), and a
    /// `usize` must hash like the same `u64` (one word, not eight bytes).
    #[test]
    fn small_integer_keys_spread_and_usize_is_one_word() {
        let mut seen = HashSet::new();
        for a in 0u32..64 {
            for b in 0u32..64 {
                assert!(seen.insert(hash_of::<IntHasher>((a, b))), "({a}, {b}) collides");
            }
        }
        assert_eq!(hash_of::<IntHasher>(12345usize), hash_of::<IntHasher>(12345u64));
    }

    /// Coordinates with all-zero low mantissa bits (0.5, 1.0, 1.5, …) must still fill the low
    /// bits that pick a bucket. 256 uniformly random hashes land in 256·(1 − (255/256)²⁵⁶) ≈ 162
    /// of 256 buckets (σ ≈ 5); without the finishing mixer these keys all share their low bits.
    #[test]
    fn round_coordinates_fill_the_low_bits() {
        let buckets: HashSet<u64> =
            (0..256).map(|i| hash_of::<BitsHasher>((i as f64 * 0.5).to_bits()) & 255).collect();
        assert!(buckets.len() >= 140, "{} buckets", buckets.len());
    }
}
