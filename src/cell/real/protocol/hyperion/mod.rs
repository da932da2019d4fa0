//! HYPERION (placeholder).
