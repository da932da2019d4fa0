//! [`PrimaryError`]: why bytes are not a valid primary interface package.

/// Why bytes are not a valid primary interface package.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PrimaryError {
    /// A size field below its header or above [`super::MAX_PACKAGE_LEN`].
    #[error("package size {0} is not in 5..=65536")]
    BadSize(i64),
    /// A field runs past the end of its package.
    #[error("a field needs {needed} bytes, {available} left")]
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Bytes left.
        available: usize,
    },
    /// A length byte that is negative.
    #[error("a negative string length")]
    BadLength,
    /// A string too long for its length byte.
    #[error("{0} bytes do not fit a one-byte length")]
    TooLong(usize),
}
