// Format version of the files results/ reads and writes (traces, metrics, beds).
namespace gravsweep::results {
int file_format_version() { return 1; }
}  // namespace gravsweep::results
