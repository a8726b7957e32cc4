# Report, summary and benchmark aggregation (issue 7).
REPORT_TARGETS = []
