// Keeps gravsweep_scheduler a valid library while queue/ and sweep/ are empty.
namespace gravsweep::db { int scheduler_link_anchor() { return 0; } }
