//! Mitsuba 3's `.serialized` mesh format.
