//! Time-domain 3D stick/slip/separation law with its derivatives (method.md §4).
