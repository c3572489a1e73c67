"""Plain NumPy oracles of the Rust kernels (slow, readable, used only by the parity tests)."""
