//! Python bindings of ballbot (the `ballbot` package's private native module).
