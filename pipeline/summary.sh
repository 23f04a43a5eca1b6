#!/usr/bin/env bash
# Prints the headline of a finished dataset run: the first table of the
# Markdown report (and the note under it when query mode could not be
# scored) and where the reports are.
# Usage: summary.sh REPORT_MD REPORT_HTML
set -euo pipefail
echo
awk '/^\|/ { print; shown = 1; next }
     shown && /^Query mode:/ { print ""; print; exit }
     shown && NF { exit }' "$1"
echo
echo "report: $2"
echo "        $1"
dir=$(dirname "$2")
if [ -d "$dir/viewer" ]; then
  echo "3D viewer: python3 -m http.server -d $dir 8000, then open http://localhost:8000/viewer/"
fi
