//! ballbot examples (see the files under this package).
