//! Atomic file writes: write a temporary file beside the target, then rename it over.
//! A crash or Ctrl-C leaves either the old file or the new one, never half a file.
