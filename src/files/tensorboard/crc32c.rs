//! CRC-32C (Castagnoli), the checksum TFRecord framing uses, and its "masked" form.
//!
//! TensorFlow's `tsl/lib/hash/crc32c.h` masks every stored checksum so that a CRC computed over
//! bytes that themselves hold CRCs does not degenerate; TensorBoard's reader unmasks and checks
//! both checksums of every record.

/// The reflected Castagnoli polynomial (0x1EDC6F41 bit-reversed).
const POLY: u32 = 0x82F6_3B78;

/// One table entry per byte value, built at compile time (byte-at-a-time CRC: fast enough for
/// a few records per evaluation).
const TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut crc = i as u32;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ POLY
            } else {
                crc >> 1
            };
            bit += 1;
        }
        table[i] = crc;
        i += 1;
    }
    table
};

/// CRC-32C of `bytes` (initial value and final XOR 0xFFFFFFFF, as iSCSI and TFRecord use).
pub fn crc32c(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc = TABLE[((crc ^ u32::from(b)) & 0xFF) as usize] ^ (crc >> 8);
    }
    !crc
}

/// The masked CRC-32C TFRecord stores: rotated right by 15 bits, plus a constant
/// (`((crc >> 15) | (crc << 17)) + 0xa282ead8`, wrapping).
pub fn masked_crc32c(bytes: &[u8]) -> u32 {
    let crc = crc32c(bytes);
    crc.rotate_right(15).wrapping_add(0xA282_EAD8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32c_matches_the_published_check_values() {
        // The standard check value (Castagnoli's CRC catalogue: "123456789" -> 0xE3069283).
        assert_eq!(crc32c(b"123456789"), 0xE306_9283);
        assert_eq!(crc32c(b""), 0);
        // RFC 3720 (iSCSI) B.4: 32 bytes of zeros, of 0xFF, and 0..=31 ascending.
        assert_eq!(crc32c(&[0u8; 32]), 0x8A91_36AA);
        assert_eq!(crc32c(&[0xFFu8; 32]), 0x62A8_AB43);
        let ascending: Vec<u8> = (0..32).collect();
        assert_eq!(crc32c(&ascending), 0x46DD_794E);
    }

    #[test]
    fn the_mask_rotates_by_15_and_adds_the_constant() {
        // Of no bytes the CRC is 0, so the mask is the constant alone (TensorBoard's
        // `masked_crc32c(b"")` is 0xa282ead8 too).
        assert_eq!(masked_crc32c(b""), 0xA282_EAD8);
        // 0xE3069283 rotated right by 15 is 0x2507C60D; plus 0xA282EAD8 is 0xC78AB0E5.
        assert_eq!(0xE306_9283u32.rotate_right(15), 0x2507_C60D);
        assert_eq!(masked_crc32c(b"123456789"), 0xC78A_B0E5);
    }
}
