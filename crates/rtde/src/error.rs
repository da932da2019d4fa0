//! [`RtdeError`]: why bytes are not a valid frame or packet.

use super::data_type::RtdeType;

/// RTDE protocol errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RtdeError {
    /// Size field below the 3-byte header.
    #[error("package size {0} is smaller than the 3-byte header")]
    BadSize(usize),
    /// Unknown package type byte.
    #[error("unknown package type {0:#04x}")]
    UnknownPackage(u8),
    /// Payload length wrong for the package type.
    #[error("package '{}' has a malformed {len}-byte payload", char::from(*kind))]
    BadPayload {
        /// Package type.
        kind: u8,
        /// Payload length.
        len: usize,
    },
    /// A name list or type list is not UTF-8.
    #[error("name or type list is not UTF-8")]
    NotUtf8,
    /// A type name not in the protocol.
    #[error("unknown type name {0:?}")]
    UnknownTypeName(String),
    /// A text message level above 3.
    #[error("text message level {0} is not 0..=3")]
    BadMessageLevel(u8),
    /// A BOOL byte other than 0 or 1.
    #[error("BOOL byte {0} is not 0 or 1")]
    BadBool(u8),
    /// Not enough bytes for a value.
    #[error("value needs {needed} bytes, {available} available")]
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Bytes there.
        available: usize,
    },
    /// A field name that cannot go on the wire.
    #[error("field name {0:?} is empty or contains a comma")]
    BadName(String),
    /// Something too long for its length field.
    #[error("{0} bytes do not fit the length field")]
    TooLong(usize),
    /// Data package for a recipe the session does not have.
    #[error("no recipe with ID {0}")]
    UnknownRecipe(u8),
    /// Data package length does not match the recipe.
    #[error("recipe {recipe_id} expects {expected} data bytes, got {got}")]
    DataLength {
        /// Recipe.
        recipe_id: u8,
        /// Expected bytes.
        expected: usize,
        /// Received bytes.
        got: usize,
    },
    /// Wrong number of values for a recipe.
    #[error("recipe {recipe_id} has {expected} fields, got {got} values")]
    ValueCount {
        /// Recipe.
        recipe_id: u8,
        /// Fields.
        expected: usize,
        /// Values.
        got: usize,
    },
    /// Value type differs from the recipe's.
    #[error("field {field} is {}, got {}", expected.name(), got.name())]
    TypeMismatch {
        /// Field name.
        field: String,
        /// Recipe type.
        expected: RtdeType,
        /// Value type.
        got: RtdeType,
    },
    /// A setup reply has a different number of types than names sent.
    #[error("setup reply has {got} types for {expected} names")]
    TypeCount {
        /// Names sent.
        expected: usize,
        /// Types received.
        got: usize,
    },
    /// The controller refused a recipe.
    #[error("recipe refused: not found {not_found:?}, in use {in_use:?}")]
    RecipeRejected {
        /// Names answered NOT_FOUND.
        not_found: Vec<String>,
        /// Names answered IN_USE.
        in_use: Vec<String>,
    },
    /// A setup reply without a pending request.
    #[error("unexpected '{0}' reply with no request pending")]
    UnexpectedReply(char),
    /// Output frequency not positive and finite.
    #[error("output frequency {0} Hz is not positive and finite")]
    BadFrequency(f64),
}
