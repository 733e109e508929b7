//! A sorted set of distinct u64 keys that answers "where is this key" in a step or two: a directory by the keys'
//! high bits narrows each search to the few keys sharing them. The mesher looks up every crossed grid edge of
//! every piece of surface, millions at a fine cell, where a binary search over the whole set took twenty steps
//! through memory that does not stay in cache.

pub(super) struct SortedKeys {
    keys: Vec<u64>,
    /// Keys are grouped by key >> shift.
    shift: u32,
    /// directory[g]: the index of the first key of group g or later; one more entry at the end.
    directory: Vec<u32>,
}

impl SortedKeys {
    /// The distinct keys of `keys`, in increasing order.
    pub fn new(mut keys: Vec<u64>) -> Self {
        use rayon::slice::ParallelSliceMut;
        keys.par_sort_unstable();
        keys.dedup();
        assert!(
            keys.len() < u32::MAX as usize,
            "too many keys for a u32 index"
        );
        let largest = keys.last().copied().unwrap_or(0);
        // About two groups a key: the smallest shift that keeps the groups' count within that.
        let wanted = 2 * keys.len() as u64 + 1;
        let shift = (0..64).find(|&s| (largest >> s) < wanted).unwrap_or(63);
        let groups = (largest >> shift) as usize + 1;
        let mut directory = Vec::with_capacity(groups + 1);
        let mut next = 0usize;
        for group in 0..=groups as u64 {
            while next < keys.len() && keys[next] >> shift < group {
                next += 1;
            }
            directory.push(next as u32);
        }
        Self {
            keys,
            shift,
            directory,
        }
    }

    pub fn keys(&self) -> &[u64] {
        &self.keys
    }

    /// The key's index in increasing order, if it is in the set.
    pub fn position(&self, key: u64) -> Option<usize> {
        let group = key >> self.shift;
        if group >= self.directory.len() as u64 - 1 {
            return None;
        }
        let group = group as usize;
        let (start, end) = (
            self.directory[group] as usize,
            self.directory[group + 1] as usize,
        );
        self.keys[start..end]
            .binary_search(&key)
            .ok()
            .map(|k| start + k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn every_key_is_found_at_its_rank_and_no_other_key_is() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(19);
        for (count, range) in [
            (0, 10u64),
            (1, 10),
            (1000, 1 << 12),
            (5000, 1 << 40),
            (300, u64::MAX),
        ] {
            // Repeats and clusters as a mesh's edge keys have them.
            let keys: Vec<u64> = (0..count)
                .map(|k| {
                    if k % 3 == 0 {
                        rng.gen_range(0..range)
                    } else {
                        (range / 2).saturating_add(k as u64 % 17)
                    }
                })
                .collect();
            let set = SortedKeys::new(keys.clone());
            let mut expected = keys.clone();
            expected.sort_unstable();
            expected.dedup();
            assert_eq!(set.keys(), &expected[..]);
            for (rank, &key) in expected.iter().enumerate() {
                assert_eq!(set.position(key), Some(rank), "{key}");
            }
            for _ in 0..1000 {
                let key = rng
                    .gen_range(0..range.max(1))
                    .saturating_add(rng.gen_range(0..3));
                assert_eq!(
                    set.position(key),
                    expected.binary_search(&key).ok(),
                    "{key}"
                );
            }
            assert_eq!(
                set.position(u64::MAX),
                expected.binary_search(&u64::MAX).ok()
            );
        }
    }
}
