//! The 1D Jenkins element (spring in series with a Coulomb slider), a special case of §4.
