//! UR RTDE (placeholder).
