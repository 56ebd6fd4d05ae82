//! Digital filters: Butterworth design, zero-phase filtering, FIR windows.
