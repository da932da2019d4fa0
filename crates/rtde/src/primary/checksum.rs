//! The calibration checksum UR's C++ client library computes from a kinematics info package
//! (`KinematicsInfo::toHash`) and compares with the one its robot description was made for:
//! `calib_` and the 64-bit `std::hash<std::string>` of libstdc++ (MurmurHash2-64A with seed
//! 0xc70f6907) over the DH parameters printed joint by joint as θ, d, a, α, each with C++
//! stream formatting (`%g`: six significant digits, trailing zeros dropped).
//!
//! Reproduced here so that a test can show which checksum the virtual UR5e's kinematics give the
//! library (the nominal UR5e's, `calib_12788084448423163542`, as URSim's), and `tendril serve`
//! can state it.

use super::state::KinematicsInfo;

/// libstdc++'s `std::_Hash_bytes` on a 64-bit target with `std::hash`'s seed.
fn libstdcxx_hash(bytes: &[u8]) -> u64 {
    const SEED: u64 = 0xc70f_6907;
    const MUL: u64 = (0xc6a4_a793_u64 << 32) + 0x5bd1_e995;
    let shift_mix = |v: u64| v ^ (v >> 47);
    let mut hash = SEED ^ (bytes.len() as u64).wrapping_mul(MUL);
    let mut chunks = bytes.chunks_exact(8);
    for chunk in &mut chunks {
        let data = u64::from_le_bytes(chunk.try_into().expect("8 bytes"));
        hash ^= shift_mix(data.wrapping_mul(MUL)).wrapping_mul(MUL);
        hash = hash.wrapping_mul(MUL);
    }
    let tail = chunks.remainder();
    if !tail.is_empty() {
        let data = tail.iter().rev().fold(0u64, |acc, &b| (acc << 8) + u64::from(b));
        hash ^= data;
        hash = hash.wrapping_mul(MUL);
    }
    shift_mix(shift_mix(hash).wrapping_mul(MUL))
}

/// A double as a C++ output stream prints it by default (`%g` with precision 6).
fn cpp_default_format(x: f64) -> String {
    if x == 0.0 {
        return if x.is_sign_negative() { "-0".into() } else { "0".into() };
    }
    if !x.is_finite() {
        return if x.is_nan() {
            "nan".into()
        } else if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    // Six significant digits fix the exponent (after rounding, as printf does).
    let scientific = format!("{x:.5e}");
    let (mantissa, exponent) = scientific.split_once('e').expect("Rust's {:e} has an exponent");
    let exponent: i32 = exponent.parse().expect("an integer exponent");
    let strip = |s: &str| -> String {
        if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s.to_string() }
    };
    if !(-4..6).contains(&exponent) {
        let sign = if exponent < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", strip(mantissa), exponent.abs())
    } else {
        strip(&format!("{x:.*}", (5 - exponent) as usize))
    }
}

impl KinematicsInfo {
    /// The checksum UR's client library computes from these DH parameters
    /// (`calib_12788084448423163542` for the nominal UR5e).
    pub fn client_library_checksum(&self) -> String {
        let mut text = String::new();
        for j in 0..6 {
            for v in [self.dh_theta[j], self.dh_d[j], self.dh_a[j], self.dh_alpha[j]] {
                text.push_str(&cpp_default_format(v));
            }
        }
        format!("calib_{}", libstdcxx_hash(text.as_bytes()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn doubles_print_as_a_cpp_stream_prints_them() {
        for (x, text) in [
            (0.0, "0"),
            (0.1625, "0.1625"),
            (-0.425, "-0.425"),
            (std::f64::consts::FRAC_PI_2, "1.5708"),
            (-std::f64::consts::FRAC_PI_2, "-1.5708"),
            (1.5707964, "1.5708"),
            (123456.0, "123456"),
            (1234567.0, "1.23457e+06"),
            (0.0001, "0.0001"),
            (0.00001234, "1.234e-05"),
            (999999.5, "1e+06"),
            (-0.0, "-0"),
            (1e-5, "1e-05"),
        ] {
            assert_eq!(cpp_default_format(x), text, "{x}");
        }
    }

    #[test]
    fn the_hash_is_libstdcxx_murmur() {
        // Values of `std::hash<std::string>` printed by a C++ program built with GCC 12 (x86-64).
        assert_eq!(libstdcxx_hash(b""), 6142509188972423790);
        assert_eq!(libstdcxx_hash(b"a"), 4993892634952068459);
        assert_eq!(libstdcxx_hash(b"abcdefgh"), 8664279048047335611);
        assert_eq!(libstdcxx_hash(b"abcdefghijk"), 3672398144843267301);
    }
}
