#!/usr/bin/env bash
# Prints the headline of a finished dataset run: the first table of the
# Markdown report and where the reports are.
# Usage: summary.sh REPORT_MD REPORT_HTML
set -euo pipefail
echo
awk '/^\|/ { print; shown = 1; next } shown { exit }' "$1"
echo
echo "report: $2"
echo "        $1"
