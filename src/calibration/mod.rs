//! The paper's calibration procedures (Sec. IV), on simulated or recorded bench data.
