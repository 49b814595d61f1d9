//! Mitsuba 3's `sdfgrid` shape and its `.vol` grid files.
