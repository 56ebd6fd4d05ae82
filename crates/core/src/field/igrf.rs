//! IGRF-14 main field (work in progress).
