//! Byte stuffing: the header pattern `FF FF FD` must not appear inside a packet body, so the
//! sender inserts `FD` after each occurrence (`FF FF FD FD`) and the receiver removes it.
//!
//! The stuffed region is everything after the instruction byte up to the CRC (parameters of an
//! instruction packet; error byte and parameters of a status packet), as in the ROBOTIS SDK and
//! the `dynamixel2` crate. The length field and the CRC cover the stuffed bytes.
//!
//! Overlapping runs count: `FF FF FF FD` is stuffed (the pattern starts at the second `FF`).
//! This matches ROBOTIS DynamixelSDK `addStuffing` byte for byte (checked against the PyPI
//! `dynamixel-sdk` for every payload of up to 7 bytes over {FF, FD, 00, 01}); `dynamixel2` 0.9.1
//! misses that overlapping case in both directions.

/// Stuffs `body`: after every `FF FF FD`, an extra `FD`.
pub fn stuff(body: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(body.len() + body.len() / 3);
    let mut run = 0; // how much of FF FF FD the last bytes match
    for &byte in body {
        out.push(byte);
        run = next_run(run, byte);
        if run == 3 {
            out.push(0xFD);
            run = 0;
        }
    }
    out
}

/// Removes the stuffing added by [`stuff`]: drops the `FD` that follows each `FF FF FD`.
///
/// Total on any input: a pattern not followed by `FD` (which a correct sender never produces)
/// is kept as it is.
pub fn unstuff(body: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(body.len());
    let mut run = 0;
    let mut skip_next_fd = false;
    for &byte in body {
        if skip_next_fd {
            skip_next_fd = false;
            if byte == 0xFD {
                run = 0;
                continue;
            }
        }
        out.push(byte);
        run = next_run(run, byte);
        if run == 3 {
            skip_next_fd = true;
            run = 0;
        }
    }
    out
}

/// Advances the match state for the pattern `FF FF FD` by one byte.
fn next_run(run: usize, byte: u8) -> usize {
    match (run, byte) {
        (0, 0xFF) | (1, 0xFF) => run + 1,
        (2, 0xFF) => 2, // FF FF FF: the last two still match the start of the pattern
        (2, 0xFD) => 3,
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pattern_gets_an_extra_fd() {
        assert_eq!(stuff(&[0x01, 0xFF, 0xFF, 0xFD, 0x02]), vec![0x01, 0xFF, 0xFF, 0xFD, 0xFD, 0x02]);
        assert_eq!(unstuff(&[0x01, 0xFF, 0xFF, 0xFD, 0xFD, 0x02]), vec![0x01, 0xFF, 0xFF, 0xFD, 0x02]);
    }

    #[test]
    fn overlapping_and_repeated_patterns() {
        let raw = [0xFF, 0xFF, 0xFF, 0xFD, 0xFF, 0xFF, 0xFD, 0xFD];
        let stuffed = stuff(&raw);
        assert_eq!(stuffed, vec![0xFF, 0xFF, 0xFF, 0xFD, 0xFD, 0xFF, 0xFF, 0xFD, 0xFD, 0xFD]);
        assert_eq!(unstuff(&stuffed), raw.to_vec());
    }

    #[test]
    fn no_pattern_no_change() {
        let raw = [0xFF, 0xFD, 0xFF, 0x00, 0xFD, 0xFD];
        assert_eq!(stuff(&raw), raw.to_vec());
        assert_eq!(unstuff(&raw), raw.to_vec());
    }
}
