//! Shared helpers for nocdyn integration tests.
