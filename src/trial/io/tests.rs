//! Tests of trial reading and writing.
