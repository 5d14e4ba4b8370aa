//! CRC-16/CCITT-FALSE, the checksum of every frame.
//!
//! Parameters (the "CRC-16/CCITT-FALSE" entry of Greg Cook's *Catalogue of
//! parametrised CRC algorithms*, also called CRC-16/IBM-3740): width 16,
//! polynomial 0x1021, initial value 0xFFFF, input and output not reflected,
//! no final XOR. Check value (the CRC of the ASCII bytes `123456789`):
//! 0x29B1. A microcontroller can compute it bit by bit as in [`crc16`]
//! (eight shifts per byte) or with the 256-entry table built by [`TABLE`].

/// The generator polynomial x¹⁶ + x¹² + x⁵ + 1.
pub const POLY: u16 = 0x1021;
/// The register's initial value.
pub const INIT: u16 = 0xFFFF;
/// The CRC of the ASCII bytes `123456789` (the catalogue's check value).
pub const CHECK: u16 = 0x29B1;

/// The byte-at-a-time lookup table (entry `b` is the CRC register after
/// shifting byte `b` through a zero register).
pub static TABLE: [u16; 256] = table();

const fn table() -> [u16; 256] {
    let mut t = [0u16; 256];
    let mut b = 0;
    while b < 256 {
        let mut r = (b as u16) << 8;
        let mut k = 0;
        while k < 8 {
            r = if r & 0x8000 != 0 { (r << 1) ^ POLY } else { r << 1 };
            k += 1;
        }
        t[b] = r;
        b += 1;
    }
    t
}

/// Continues a CRC over `data` from register value `crc` (start with
/// [`INIT`]).
pub fn update(mut crc: u16, data: &[u8]) -> u16 {
    for &b in data {
        crc = (crc << 8) ^ TABLE[((crc >> 8) as u8 ^ b) as usize];
    }
    crc
}

/// The CRC-16/CCITT-FALSE of `data`.
pub fn crc16(data: &[u8]) -> u16 {
    update(INIT, data)
}

/// The same CRC computed bit by bit, the way a small microcontroller
/// without room for the table would (kept to check the table against).
pub fn crc16_bitwise(data: &[u8]) -> u16 {
    let mut crc = INIT;
    for &b in data {
        crc ^= (b as u16) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 { (crc << 1) ^ POLY } else { crc << 1 };
        }
    }
    crc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_value_of_the_catalogue() {
        assert_eq!(crc16(b"123456789"), 0x29B1);
        assert_eq!(crc16(b"123456789"), CHECK);
        assert_eq!(crc16_bitwise(b"123456789"), CHECK);
    }

    #[test]
    fn empty_input_leaves_the_initial_value() {
        assert_eq!(crc16(&[]), INIT);
    }

    #[test]
    fn table_and_bitwise_agree_and_updates_chain() {
        let data: Vec<u8> = (0..=255u8).chain((0..=255u8).rev()).collect();
        assert_eq!(crc16(&data), crc16_bitwise(&data));
        let (a, b) = data.split_at(100);
        assert_eq!(update(update(INIT, a), b), crc16(&data));
        // Table entry 1 is the polynomial itself.
        assert_eq!(TABLE[1], POLY);
    }

    #[test]
    fn every_single_bit_flip_changes_the_crc() {
        let data = *b"evflow serial frame";
        let c = crc16(&data);
        for i in 0..data.len() * 8 {
            let mut d = data;
            d[i / 8] ^= 1 << (i % 8);
            assert_ne!(crc16(&d), c, "bit {i}");
        }
    }
}
