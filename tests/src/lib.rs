//! Helpers shared by figurine's end-to-end tests.
