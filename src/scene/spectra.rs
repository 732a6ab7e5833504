//! Spectra to RGB as Mitsuba 3's RGB variants do it, and named IORs and metals.
