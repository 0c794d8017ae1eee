//! The few pieces of the protocol-buffer wire format an event file needs, by hand: varints,
//! field keys, and length-delimited, 64-bit and 32-bit fields
//! (<https://protobuf.dev/programming-guides/encoding/>). A parser for the same subset reads
//! fields back, skipping those it does not know, as any protobuf reader does.

/// How a field's value is laid out after its key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WireType {
    /// A varint (int64, enums).
    Varint = 0,
    /// Eight little-endian bytes (double).
    Fixed64 = 1,
    /// A varint length, then that many bytes (string, bytes, embedded message).
    Len = 2,
    /// Four little-endian bytes (float).
    Fixed32 = 5,
}

/// Append `value` as a varint: seven bits per byte, least significant first, the high bit set
/// on every byte but the last. A negative int64 is its two's complement (ten bytes).
pub fn put_varint(out: &mut Vec<u8>, mut value: u64) {
    while value >= 0x80 {
        out.push((value as u8 & 0x7F) | 0x80);
        value >>= 7;
    }
    out.push(value as u8);
}

/// Append the key of field `number`: `(number << 3) | wire type`, as a varint.
pub fn put_key(out: &mut Vec<u8>, number: u32, wire: WireType) {
    put_varint(out, (u64::from(number) << 3) | wire as u64);
}

/// Append a length-delimited field (a string or an embedded message's bytes).
pub fn put_bytes(out: &mut Vec<u8>, number: u32, bytes: &[u8]) {
    put_key(out, number, WireType::Len);
    put_varint(out, bytes.len() as u64);
    out.extend_from_slice(bytes);
}

/// Append a double field.
pub fn put_f64(out: &mut Vec<u8>, number: u32, value: f64) {
    put_key(out, number, WireType::Fixed64);
    out.extend_from_slice(&value.to_le_bytes());
}

/// Append a float field.
pub fn put_f32(out: &mut Vec<u8>, number: u32, value: f32) {
    put_key(out, number, WireType::Fixed32);
    out.extend_from_slice(&value.to_le_bytes());
}

/// Append a varint field (int64 as its two's complement, an enum as its number).
pub fn put_varint_field(out: &mut Vec<u8>, number: u32, value: u64) {
    put_key(out, number, WireType::Varint);
    put_varint(out, value);
}

/// One field as read: its number and value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Field<'a> {
    /// A varint field's value.
    Varint(u32, u64),
    /// A 64-bit field's bits.
    Fixed64(u32, u64),
    /// A length-delimited field's bytes.
    Len(u32, &'a [u8]),
    /// A 32-bit field's bits.
    Fixed32(u32, u32),
}

/// Read a varint at `*at`, moving past it; `None` when the bytes end first or it runs past ten
/// bytes.
pub fn get_varint(bytes: &[u8], at: &mut usize) -> Option<u64> {
    let mut value = 0u64;
    for shift in (0..70).step_by(7) {
        let b = *bytes.get(*at)?;
        *at += 1;
        value |= u64::from(b & 0x7F) << shift;
        if b & 0x80 == 0 {
            return Some(value);
        }
    }
    None
}

/// The next `n` bytes at `*at`, moving past them; `None` when fewer remain.
fn take<'a>(bytes: &'a [u8], at: &mut usize, n: usize) -> Option<&'a [u8]> {
    let end = at.checked_add(n).filter(|&e| e <= bytes.len())?;
    let slice = &bytes[*at..end];
    *at = end;
    Some(slice)
}

/// Every field of one message, in order; an error names the byte offset where the message stops
/// making sense (a truncated value, an unknown wire type).
pub fn fields(bytes: &[u8]) -> Result<Vec<Field<'_>>, String> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let start = at;
        let bad = |what: &str| format!("byte {start}: {what}");
        let truncated = || bad("truncated field");
        let key = get_varint(bytes, &mut at).ok_or_else(truncated)?;
        let number = u32::try_from(key >> 3).map_err(|_| bad("field number out of range"))?;
        let field = match key & 7 {
            0 => Field::Varint(number, get_varint(bytes, &mut at).ok_or_else(truncated)?),
            1 => {
                let b = take(bytes, &mut at, 8).ok_or_else(truncated)?;
                Field::Fixed64(number, u64::from_le_bytes(b.try_into().expect("8 bytes")))
            }
            2 => {
                let len = get_varint(bytes, &mut at).ok_or_else(truncated)?;
                let len = usize::try_from(len).map_err(|_| truncated())?;
                Field::Len(number, take(bytes, &mut at, len).ok_or_else(truncated)?)
            }
            5 => {
                let b = take(bytes, &mut at, 4).ok_or_else(truncated)?;
                Field::Fixed32(number, u32::from_le_bytes(b.try_into().expect("4 bytes")))
            }
            other => return Err(bad(&format!("wire type {other} is not read here"))),
        };
        out.push(field);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn varint(v: u64) -> Vec<u8> {
        let mut out = Vec::new();
        put_varint(&mut out, v);
        out
    }

    #[test]
    fn varints_take_seven_bits_per_byte_low_first() {
        assert_eq!(varint(0), [0x00]);
        assert_eq!(varint(1), [0x01]);
        assert_eq!(varint(127), [0x7F]);
        // 150 = 0b1_0010110: 0x96 (0010110 with the continuation bit), then 0x01 (the spec's
        // own example).
        assert_eq!(varint(150), [0x96, 0x01]);
        assert_eq!(varint(300), [0xAC, 0x02]);
        // int64 -1 is ten bytes: nine 0xFF, then 0x01.
        assert_eq!(
            varint(-1i64 as u64),
            [0xFF; 9].iter().chain(&[0x01]).copied().collect::<Vec<_>>()
        );
        for v in [
            0,
            1,
            127,
            128,
            150,
            16_383,
            16_384,
            u64::from(u32::MAX),
            u64::MAX,
        ] {
            let bytes = varint(v);
            let mut at = 0;
            assert_eq!(get_varint(&bytes, &mut at), Some(v));
            assert_eq!(at, bytes.len());
        }
        // A varint whose bytes end early is no varint.
        assert_eq!(get_varint(&[0x96], &mut 0), None);
    }

    #[test]
    fn keys_hold_the_field_number_and_wire_type() {
        let mut out = Vec::new();
        // Event.wall_time (1, double), step (2, varint), file_version (3, string),
        // Summary.Value.simple_value (2, float): the bytes TensorBoard's files start fields with.
        put_key(&mut out, 1, WireType::Fixed64);
        put_key(&mut out, 2, WireType::Varint);
        put_key(&mut out, 3, WireType::Len);
        put_key(&mut out, 2, WireType::Fixed32);
        assert_eq!(out, [0x09, 0x10, 0x1A, 0x15]);
    }

    #[test]
    fn fields_read_back_what_was_put_and_a_cut_message_is_named() {
        let mut m = Vec::new();
        put_f64(&mut m, 1, 1.5);
        put_varint_field(&mut m, 2, 40);
        put_bytes(&mut m, 3, b"brain.Event:2");
        put_f32(&mut m, 9, -3.5);
        assert_eq!(
            fields(&m).unwrap(),
            [
                Field::Fixed64(1, 1.5f64.to_bits()),
                Field::Varint(2, 40),
                Field::Len(3, b"brain.Event:2"),
                Field::Fixed32(9, (-3.5f32).to_bits()),
            ]
        );
        let cut = &m[..m.len() - 1];
        let e = fields(cut).unwrap_err();
        assert_eq!(e, format!("byte {}: truncated field", m.len() - 5));
        assert!(fields(&[0x0B]).unwrap_err().contains("wire type 3"));
    }
}
