//! TFRecord framing, the container of an event file: each record is its length (u64,
//! little-endian), the masked CRC-32C of those eight bytes, the data, and the masked CRC-32C of
//! the data (TensorFlow's `tsl/lib/io/record_writer.cc`). A reader checks both checksums, so a
//! record cut short by a killed writer is found, not misread.

use super::crc32c::masked_crc32c;

/// Bytes a record adds around its data: length, its checksum, the data's checksum.
const OVERHEAD: usize = 8 + 4 + 4;

/// `data` framed as one record.
pub fn frame(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len() + OVERHEAD);
    let len = (data.len() as u64).to_le_bytes();
    out.extend_from_slice(&len);
    out.extend_from_slice(&masked_crc32c(&len).to_le_bytes());
    out.extend_from_slice(data);
    out.extend_from_slice(&masked_crc32c(data).to_le_bytes());
    out
}

/// Why the records of a file could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RecordError {
    /// The bytes end inside a record (a writer killed mid-record leaves this at the end).
    #[error("byte {offset}: the file ends inside a record")]
    Truncated {
        /// Where the record starts.
        offset: usize,
    },
    /// A stored checksum does not match the bytes it covers.
    #[error("byte {offset}: the {what} checksum does not match")]
    BadChecksum {
        /// Where the record starts.
        offset: usize,
        /// `length` or `data`.
        what: &'static str,
    },
}

/// The data of every record in `bytes`, in order, both checksums checked.
pub fn unframe(bytes: &[u8]) -> Result<Vec<&[u8]>, RecordError> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let offset = at;
        let truncated = RecordError::Truncated { offset };
        let header = bytes.get(at..at + 12).ok_or(truncated.clone())?;
        let (len_bytes, len_crc) = header.split_at(8);
        if masked_crc32c(len_bytes).to_le_bytes() != len_crc {
            return Err(RecordError::BadChecksum {
                offset,
                what: "length",
            });
        }
        let len = u64::from_le_bytes(len_bytes.try_into().expect("8 bytes"));
        let data_end = usize::try_from(len)
            .ok()
            .and_then(|l| (at + 12).checked_add(l))
            .filter(|&end| end + 4 <= bytes.len())
            .ok_or(truncated)?;
        let data = &bytes[at + 12..data_end];
        if masked_crc32c(data).to_le_bytes() != bytes[data_end..data_end + 4] {
            return Err(RecordError::BadChecksum {
                offset,
                what: "data",
            });
        }
        out.push(data);
        at = data_end + 4;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_is_length_its_checksum_data_and_the_datas_checksum() {
        // The first record of an event file: TensorBoard's own bytes (tensorboard 2.21's
        // record framing of `Event(wall_time=1.5, file_version="brain.Event:2")`).
        let data = b"\x09\x00\x00\x00\x00\x00\x00\xf8\x3f\x1a\x0dbrain.Event:2";
        let framed = frame(data);
        assert_eq!(&framed[..8], &24u64.to_le_bytes());
        // Masked CRC-32C of the eight length bytes, then of the data, little-endian.
        assert_eq!(&framed[8..12], &[0xa3, 0x7f, 0x4b, 0x22]);
        assert_eq!(&framed[12..36], data);
        assert_eq!(&framed[36..], &[0x2a, 0x28, 0x64, 0x6c]);
        assert_eq!(unframe(&framed).unwrap(), [&data[..]]);
    }

    #[test]
    fn an_empty_record_carries_the_mask_constant_as_its_data_checksum() {
        // CRC-32C of no bytes is 0, so its masked form is 0xa282ead8 alone.
        let framed = frame(b"");
        assert_eq!(framed.len(), OVERHEAD);
        assert_eq!(&framed[12..], &0xA282_EAD8u32.to_le_bytes());
        assert_eq!(unframe(&framed).unwrap(), [&b""[..]]);
    }

    #[test]
    fn a_cut_or_damaged_record_is_found() {
        let mut two = frame(b"first");
        two.extend(frame(b"second"));
        assert_eq!(unframe(&two).unwrap(), [&b"first"[..], b"second"]);
        let second_at = OVERHEAD + 5;
        assert_eq!(
            unframe(&two[..two.len() - 1]),
            Err(RecordError::Truncated { offset: second_at })
        );
        let mut flipped = two.clone();
        flipped[second_at + 12] ^= 1;
        assert_eq!(
            unframe(&flipped),
            Err(RecordError::BadChecksum {
                offset: second_at,
                what: "data"
            })
        );
        flipped[second_at] ^= 1;
        assert_eq!(
            unframe(&flipped),
            Err(RecordError::BadChecksum {
                offset: second_at,
                what: "length"
            })
        );
    }
}
