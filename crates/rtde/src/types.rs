//! RTDE data types and values (big-endian on the wire).

use super::RtdeError;
pub use super::data_type::RtdeType;

/// The type entry of a setup reply: a type, or the controller's reason for refusing the name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldType {
    /// The field exists and has this type.
    Known(RtdeType),
    /// No field of that name (`NOT_FOUND`).
    NotFound,
    /// An input already written by another client (`IN_USE`).
    InUse,
}

impl FieldType {
    /// The name used in setup replies.
    pub fn name(self) -> &'static str {
        match self {
            FieldType::Known(t) => t.name(),
            FieldType::NotFound => "NOT_FOUND",
            FieldType::InUse => "IN_USE",
        }
    }

    /// Parses a setup-reply entry.
    pub fn from_name(name: &str) -> Result<FieldType, RtdeError> {
        match name {
            "NOT_FOUND" => Ok(FieldType::NotFound),
            "IN_USE" => Ok(FieldType::InUse),
            other => RtdeType::from_name(other)
                .map(FieldType::Known)
                .ok_or_else(|| RtdeError::UnknownTypeName(other.to_string())),
        }
    }
}

/// One field value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RtdeValue {
    /// BOOL.
    Bool(bool),
    /// UINT8.
    Uint8(u8),
    /// UINT32.
    Uint32(u32),
    /// UINT64.
    Uint64(u64),
    /// INT32.
    Int32(i32),
    /// DOUBLE.
    Double(f64),
    /// VECTOR3D.
    Vector3d([f64; 3]),
    /// VECTOR6D.
    Vector6d([f64; 6]),
    /// VECTOR6INT32.
    Vector6Int32([i32; 6]),
    /// VECTOR6UINT32.
    Vector6Uint32([u32; 6]),
}

impl RtdeValue {
    /// The value's type.
    pub fn rtde_type(&self) -> RtdeType {
        match self {
            RtdeValue::Bool(_) => RtdeType::Bool,
            RtdeValue::Uint8(_) => RtdeType::Uint8,
            RtdeValue::Uint32(_) => RtdeType::Uint32,
            RtdeValue::Uint64(_) => RtdeType::Uint64,
            RtdeValue::Int32(_) => RtdeType::Int32,
            RtdeValue::Double(_) => RtdeType::Double,
            RtdeValue::Vector3d(_) => RtdeType::Vector3d,
            RtdeValue::Vector6d(_) => RtdeType::Vector6d,
            RtdeValue::Vector6Int32(_) => RtdeType::Vector6Int32,
            RtdeValue::Vector6Uint32(_) => RtdeType::Vector6Uint32,
        }
    }

    /// The zero value of a type.
    pub fn zero(t: RtdeType) -> RtdeValue {
        match t {
            RtdeType::Bool => RtdeValue::Bool(false),
            RtdeType::Uint8 => RtdeValue::Uint8(0),
            RtdeType::Uint32 => RtdeValue::Uint32(0),
            RtdeType::Uint64 => RtdeValue::Uint64(0),
            RtdeType::Int32 => RtdeValue::Int32(0),
            RtdeType::Double => RtdeValue::Double(0.0),
            RtdeType::Vector3d => RtdeValue::Vector3d([0.0; 3]),
            RtdeType::Vector6d => RtdeValue::Vector6d([0.0; 6]),
            RtdeType::Vector6Int32 => RtdeValue::Vector6Int32([0; 6]),
            RtdeType::Vector6Uint32 => RtdeValue::Vector6Uint32([0; 6]),
        }
    }

    /// Appends the big-endian encoding.
    pub fn encode_into(&self, out: &mut Vec<u8>) {
        match self {
            RtdeValue::Bool(v) => out.push(u8::from(*v)),
            RtdeValue::Uint8(v) => out.push(*v),
            RtdeValue::Uint32(v) => out.extend_from_slice(&v.to_be_bytes()),
            RtdeValue::Uint64(v) => out.extend_from_slice(&v.to_be_bytes()),
            RtdeValue::Int32(v) => out.extend_from_slice(&v.to_be_bytes()),
            RtdeValue::Double(v) => out.extend_from_slice(&v.to_be_bytes()),
            RtdeValue::Vector3d(v) => v.iter().for_each(|x| out.extend_from_slice(&x.to_be_bytes())),
            RtdeValue::Vector6d(v) => v.iter().for_each(|x| out.extend_from_slice(&x.to_be_bytes())),
            RtdeValue::Vector6Int32(v) => v.iter().for_each(|x| out.extend_from_slice(&x.to_be_bytes())),
            RtdeValue::Vector6Uint32(v) => v.iter().for_each(|x| out.extend_from_slice(&x.to_be_bytes())),
        }
    }

    /// Decodes a value of type `t` from the front of `bytes`; returns it and the bytes used.
    pub fn decode(t: RtdeType, bytes: &[u8]) -> Result<(RtdeValue, usize), RtdeError> {
        let size = t.size();
        let b = bytes.get(..size).ok_or(RtdeError::Truncated { needed: size, available: bytes.len() })?;
        let w4 = |i: usize| [b[i], b[i + 1], b[i + 2], b[i + 3]];
        let w8 = |i: usize| [b[i], b[i + 1], b[i + 2], b[i + 3], b[i + 4], b[i + 5], b[i + 6], b[i + 7]];
        let value = match t {
            RtdeType::Bool => match b[0] {
                0 => RtdeValue::Bool(false),
                1 => RtdeValue::Bool(true),
                other => return Err(RtdeError::BadBool(other)),
            },
            RtdeType::Uint8 => RtdeValue::Uint8(b[0]),
            RtdeType::Uint32 => RtdeValue::Uint32(u32::from_be_bytes(w4(0))),
            RtdeType::Uint64 => RtdeValue::Uint64(u64::from_be_bytes(w8(0))),
            RtdeType::Int32 => RtdeValue::Int32(i32::from_be_bytes(w4(0))),
            RtdeType::Double => RtdeValue::Double(f64::from_be_bytes(w8(0))),
            RtdeType::Vector3d => RtdeValue::Vector3d(std::array::from_fn(|k| f64::from_be_bytes(w8(8 * k)))),
            RtdeType::Vector6d => RtdeValue::Vector6d(std::array::from_fn(|k| f64::from_be_bytes(w8(8 * k)))),
            RtdeType::Vector6Int32 => RtdeValue::Vector6Int32(std::array::from_fn(|k| i32::from_be_bytes(w4(4 * k)))),
            RtdeType::Vector6Uint32 => RtdeValue::Vector6Uint32(std::array::from_fn(|k| u32::from_be_bytes(w4(4 * k)))),
        };
        Ok((value, size))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_match_the_guide() {
        let sizes: Vec<usize> = RtdeType::ALL.iter().map(|t| t.size()).collect();
        assert_eq!(sizes, vec![1, 1, 4, 8, 4, 8, 24, 48, 24, 24]);
    }

    #[test]
    fn names_round_trip() {
        for t in RtdeType::ALL {
            assert_eq!(FieldType::from_name(t.name()).unwrap(), FieldType::Known(t));
        }
        assert_eq!(FieldType::from_name("IN_USE").unwrap(), FieldType::InUse);
        assert!(FieldType::from_name("FLOAT").is_err());
    }

    #[test]
    fn every_type_round_trips() {
        let values = [
            RtdeValue::Bool(true),
            RtdeValue::Uint8(200),
            RtdeValue::Uint32(0xDEAD_BEEF),
            RtdeValue::Uint64(u64::MAX - 7),
            RtdeValue::Int32(-7),
            RtdeValue::Double(1.5),
            RtdeValue::Vector3d([1.0, -2.0, 3.5]),
            RtdeValue::Vector6d([0.1, 0.2, 0.3, -0.4, 0.5, 0.6]),
            RtdeValue::Vector6Int32([-1, 2, -3, 4, -5, 6]),
            RtdeValue::Vector6Uint32([1, 2, 3, 4, 5, u32::MAX]),
        ];
        for v in values {
            let mut bytes = Vec::new();
            v.encode_into(&mut bytes);
            assert_eq!(bytes.len(), v.rtde_type().size());
            assert_eq!(RtdeValue::decode(v.rtde_type(), &bytes).unwrap(), (v, bytes.len()));
        }
        assert!(RtdeValue::decode(RtdeType::Double, &[0; 7]).is_err());
        assert!(RtdeValue::decode(RtdeType::Bool, &[2]).is_err());
    }
}
