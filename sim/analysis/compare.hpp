// `tpsim compare`: several statistics files side by side, each later run as a ratio to the
// first, with what differs in their setup and in their images.
#pragma once
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "sim/analysis/images.hpp"
#include "sim/analysis/stats_file.hpp"

namespace tpsim::analysis {

/// Which way a statistic improves, to tell a better run from a worse one.
enum class Better { neutral, higher, lower };

/// One statistic across the runs.
struct Row {
    std::string key;  ///< the statistic's key, or a name for a figure derived from several
    std::string unit;
    Better better = Better::neutral;
    std::vector<std::optional<double>> values;  ///< one per run; absent where a run lacks it
    /// One per run (or none: all exact): the half-width of a sampled run's confidence interval
    /// around its estimate; 0 for an exact value; NaN for an estimate whose interval is unknown.
    std::vector<double> intervals;

    double interval(size_t run) const { return intervals.empty() ? 0.0 : intervals.at(run); }
    /// Is values[run] an estimate (of a sampled run) rather than a count?
    bool estimated(size_t run) const { return interval(run) != 0; }
    /// True when run's value and the first run's differ by less than their intervals together:
    /// the estimates cannot tell them apart (never for two exact values).
    bool within_intervals(size_t run) const;

    /// values[run] / values[0]; 1 when both are 0; absent when either is absent, or only the
    /// first is 0.
    std::optional<double> ratio(size_t run) const;
    /// True when the ratio to the first run is outside 0.95 .. 1.05.
    bool differs_notably(size_t run) const;
};

/// The row as a person reads it: seconds and joules with the SI prefix that suits its largest
/// value (2.85e-06 J -> 2.85 µJ); other units as they are. The CSV and JSON keep SI units.
Row for_display(const Row& row);

struct Section {
    std::string title;
    std::vector<Row> rows;
};

/// A setup field (run field or configuration key) whose value is not the same in every run.
struct SetupDifference {
    std::string field;
    std::vector<std::string> values;  ///< one per run, "(absent)" where a run lacks it
};

struct Comparison {
    std::vector<std::string> runs;  ///< the files, as given
    std::vector<SetupDifference> differences;
    std::vector<Section> sections;  ///< summary, stalls, FU utilisation, traffic, per ray,
                                    ///< energy and area by part
    /// images[i - 1]: run i's image against run 0's; absent when neither names an image.
    std::vector<std::optional<ImageDifference>> images;
    Row host;  ///< host wall time of the kernel run: shown apart, never as a result
    /// One per run: empty for a run of measured figures; for a sampled run, what its estimates
    /// are ("estimates at 95 % confidence from 45 units ...").
    std::vector<std::string> estimates;
};

/// `keys`, when not empty, keeps only the rows whose key matches one of these shell patterns
/// ("chip/cycles", "region/bvh_nodes/*"), and the sections that still have rows.
Comparison compare(const std::vector<StatsFile>& runs, const std::vector<std::string>& keys = {});

enum class Format { text, markdown, csv, json };

/// Writes the comparison; `colour` marks notable ratios with ANSI colours (text only).
void write_comparison(const Comparison& comparison, Format format, std::ostream& out,
                      bool colour = false);

/// How the tables name run i: A, B, ... Z, then R27, R28 ...
std::string run_letter(size_t run);

/// A number as the tables show it: whole numbers exactly, others to 4 significant digits.
std::string format_number(double value);

/// A CSV field (RFC 4180): quoted, with quotes doubled, when it holds a comma, a quote or a
/// line break.
std::string csv_field(const std::string& text);

}  // namespace tpsim::analysis
