//! [`RtdeType`]: the data type of a recipe field, its name and its size on the wire. Apart from
//! the values ([`crate::types`]) so that the errors ([`crate::RtdeError`]) can name a type.

/// A data type of a recipe field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RtdeType {
    /// 1 byte, 0 or 1.
    Bool,
    /// 1 byte.
    Uint8,
    /// 4 bytes.
    Uint32,
    /// 8 bytes.
    Uint64,
    /// 4 bytes, signed.
    Int32,
    /// 8 bytes, IEEE 754.
    Double,
    /// 3 doubles.
    Vector3d,
    /// 6 doubles.
    Vector6d,
    /// 6 signed 32-bit integers.
    Vector6Int32,
    /// 6 unsigned 32-bit integers.
    Vector6Uint32,
}

impl RtdeType {
    /// Every type.
    pub const ALL: [RtdeType; 10] = [
        RtdeType::Bool,
        RtdeType::Uint8,
        RtdeType::Uint32,
        RtdeType::Uint64,
        RtdeType::Int32,
        RtdeType::Double,
        RtdeType::Vector3d,
        RtdeType::Vector6d,
        RtdeType::Vector6Int32,
        RtdeType::Vector6Uint32,
    ];

    /// The name used in setup replies.
    pub fn name(self) -> &'static str {
        match self {
            RtdeType::Bool => "BOOL",
            RtdeType::Uint8 => "UINT8",
            RtdeType::Uint32 => "UINT32",
            RtdeType::Uint64 => "UINT64",
            RtdeType::Int32 => "INT32",
            RtdeType::Double => "DOUBLE",
            RtdeType::Vector3d => "VECTOR3D",
            RtdeType::Vector6d => "VECTOR6D",
            RtdeType::Vector6Int32 => "VECTOR6INT32",
            RtdeType::Vector6Uint32 => "VECTOR6UINT32",
        }
    }

    /// The type with this name.
    pub fn from_name(name: &str) -> Option<RtdeType> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    /// Size on the wire in bytes.
    pub fn size(self) -> usize {
        match self {
            RtdeType::Bool | RtdeType::Uint8 => 1,
            RtdeType::Uint32 | RtdeType::Int32 => 4,
            RtdeType::Uint64 | RtdeType::Double => 8,
            RtdeType::Vector3d | RtdeType::Vector6Int32 | RtdeType::Vector6Uint32 => 24,
            RtdeType::Vector6d => 48,
        }
    }
}
