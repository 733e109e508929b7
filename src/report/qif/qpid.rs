//! The QPId (QIF persistent identifier, a UUID) of a results document. It is derived from what identifies the
//! inspection (job, serial, finish time), so writing the same report twice gives the same QPId and two
//! inspections give different ones, without a UUID crate or a random source.

/// A version-8 (application-defined) UUID whose 122 free bits are the FNV-1a 128-bit hash of the job, the serial
/// and the finish time of the inspection.
pub(super) fn inspection_qpid(job: &str, serial: &str, finished: &str) -> String {
    // Each field is followed by a zero byte, so that ("ab", "c") and ("a", "bc") differ.
    let fields = [job, serial, finished];
    let hash = fnv1a_128(fields.iter().flat_map(|field| field.bytes().chain([0])));
    let version_and_variant = (hash & !(0xF << 76) & !(0b11 << 62)) | (0x8 << 76) | (0b10 << 62);
    let hex = format!("{version_and_variant:032x}");
    format!(
        "{}-{}-{}-{}-{}",
        &hex[0..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..32]
    )
}

/// FNV-1a, 128-bit (offset basis and prime from the FNV specification).
fn fnv1a_128(bytes: impl IntoIterator<Item = u8>) -> u128 {
    const OFFSET_BASIS: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013b;
    bytes.into_iter().fold(OFFSET_BASIS, |hash, byte| {
        (hash ^ u128::from(byte)).wrapping_mul(PRIME)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_qpid_is_a_version_8_uuid_fixed_by_the_inspection() {
        let qpid = inspection_qpid("job-17", "SN-0042", "2025-03-04T10:20:00Z");
        let groups: Vec<&str> = qpid.split('-').collect();
        assert_eq!(
            groups.iter().map(|g| g.len()).collect::<Vec<_>>(),
            [8, 4, 4, 4, 12],
            "{qpid}"
        );
        assert!(
            qpid.chars().all(|c| c == '-' || c.is_ascii_hexdigit()),
            "{qpid}"
        );
        assert!(groups[2].starts_with('8'), "version nibble: {qpid}");
        assert!("89ab".contains(&groups[3][..1]), "variant bits: {qpid}");
        assert_eq!(
            qpid,
            inspection_qpid("job-17", "SN-0042", "2025-03-04T10:20:00Z")
        );
        assert_ne!(
            qpid,
            inspection_qpid("job-17", "SN-0043", "2025-03-04T10:20:00Z")
        );
        assert_ne!(
            inspection_qpid("ab", "c", "t"),
            inspection_qpid("a", "bc", "t")
        );
    }

    #[test]
    fn fnv1a_128_matches_the_published_test_vectors() {
        assert_eq!(fnv1a_128([]), 0x6c62272e07bb014262b821756295c58d);
        assert_eq!(fnv1a_128(*b"a"), 0xd228cb696f1a8caf78912b704e4a8964);
    }
}
