//! ballbot benches (see the files under this package).
