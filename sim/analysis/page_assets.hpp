// The page's style sheet and script (report_page.css, report_page.js), built into tpsim.
#pragma once

namespace tpsim::analysis {
extern const char* const kReportPageCss;
extern const char* const kReportPageJs;
}  // namespace tpsim::analysis
