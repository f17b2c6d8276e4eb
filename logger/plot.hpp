#pragma once

/// Plots drawn by gnuplot (Debian's gnuplot-nox, its `pngcairo` terminal), run as a subprocess.
/// A figure is three files side by side: NAME.dat (the numbers), NAME.gp (the script, which reads
/// NAME.dat and writes NAME.png by relative names) and NAME.png. gnuplot runs in that directory,
/// so a researcher can edit the script and re-run it by hand:
///
///     cd session.report && gnuplot xy.gp          # xy.dat -> xy.png
///
/// In code:
///
///     GnuplotData data;
///     const int truth = data.add_block("true path: X (m), Y (m)", {{0.5, 0.0}, {0.6, 0.1}});
///     data.save(dir + "/xy.dat");
///     write_text_file(dir + "/xy.gp", "set terminal pngcairo size 800,800\n"
///                                     "set output 'xy.png'\n"
///                                     "plot 'xy.dat' index " + std::to_string(truth) +
///                                     " with lines title " + gnuplot_string("true") + "\n");
///     run_gnuplot(find_gnuplot(), dir, "xy.gp");  // throws GnuplotMissing or PlotError
///
/// Text that reaches a script (titles, event names, channel names from a log) goes through
/// gnuplot_string(), which quotes it so that it can only ever be a string: nothing a log holds
/// can run as a gnuplot command.

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace sg::logger {

/// A figure could not be made: gnuplot failed, or a file could not be written. One line that
/// names the file (and gnuplot's own message).
struct PlotError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// No gnuplot to run (not installed, not on PATH, or the given path is not an executable).
struct GnuplotMissing : PlotError {
  using PlotError::PlotError;
};

/// A colour as 8-bit red, green, blue.
struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  /// "#rrggbb", as gnuplot takes it in `lc rgb '#1f77b4'`.
  std::string hex() const;
};

/// The figures' colours: matplotlib's "tab10" hues, a light shade for bands, a muted red for
/// notes ("no data").
namespace palette {
inline constexpr Rgb kBlue{31, 119, 180};
inline constexpr Rgb kDarkBlue{31, 78, 121};  ///< bar borders
inline constexpr Rgb kOrange{255, 127, 14};
inline constexpr Rgb kGreen{44, 160, 44};
inline constexpr Rgb kPurple{148, 103, 189};
inline constexpr Rgb kGrid{221, 221, 221};
inline constexpr Rgb kBorder{51, 51, 51};
/// Shaded bands (occlusions), filled flat, so this exact value is in the PNG.
inline constexpr Rgb kShade{255, 228, 181};
inline constexpr Rgb kNote{190, 70, 70};
inline constexpr Rgb kBackground{255, 255, 255};
}  // namespace palette

/// The numbers of one data file, in blocks that a script selects with `index N`. A row holding
/// a non-finite value is not written: it becomes a blank line, which breaks a line drawn `with
/// lines` there (consecutive breaks collapse into one; two blank lines would start a new block).
class GnuplotData {
 public:
  /// Appends a block, preceded by `# comment` (made single-line), and returns its index; a block
  /// without a finite row is not written and gives -1 (so a script can leave that series out:
  /// gnuplot refuses to plot an empty block).
  int add_block(const std::string& comment, const std::vector<std::vector<double>>& rows);
  /// Rows written in block `index` (0 for -1 or an unknown index).
  int64_t rows(int index) const;
  int blocks() const { return static_cast<int>(rows_.size()); }

  const std::string& text() const { return text_; }
  /// Writes text() to `path`; throws PlotError naming the path.
  void save(const std::string& path) const;

 private:
  std::string text_;
  std::vector<int64_t> rows_;
};

/// `text` as a gnuplot single-quoted string: quote marks doubled, control characters and bytes
/// outside printable ASCII replaced by '?', at most `max_chars` characters (longer text ends in
/// "..."). Safe for any input.
std::string gnuplot_string(const std::string& text, size_t max_chars = 200);

/// A number as gnuplot reads it back exactly enough for plotting (%.10g); "NaN" for NaN, and
/// "1e308"/"-1e308" for infinities.
std::string gnuplot_number(double value);

/// Writes `text` to `path` (replacing it); throws PlotError naming the path.
void write_text_file(const std::string& path, const std::string& text);

/// The gnuplot executable to run: `program` itself when it holds a '/', otherwise the first
/// executable `program` in the directories of PATH. Throws GnuplotMissing, one line saying
/// what was looked for and that Debian's package is gnuplot-nox.
std::string find_gnuplot(const std::string& program = "gnuplot");

/// Runs `gnuplot script` with `dir` as its working directory (stdin and stdout /dev/null,
/// stderr captured). Throws PlotError naming dir/script and gnuplot's message (the last line it
/// wrote, which is where gnuplot reports an error) when gnuplot cannot start, exits non-zero,
/// is killed by a signal, or runs past `timeout` (it is then killed).
void run_gnuplot(const std::string& gnuplot, const std::string& dir, const std::string& script,
                 std::chrono::milliseconds timeout = std::chrono::seconds(60));

}  // namespace sg::logger
