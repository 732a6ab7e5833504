//! Tone mapping for previews.
