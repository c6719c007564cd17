//! figurine wire protocol (work in progress in this commit).
#![no_std]
#![forbid(unsafe_code)]
