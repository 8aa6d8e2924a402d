# Sourced by the check scripts (tool_checks, check_build_modes): writes one
# JUnit result file for scripts/test to count, and prints the outcome.
#   junit_result DIR SUITE LABEL NAME OK(0/1) MESSAGE
# -> DIR/NAME.xml (testsuite SUITE, testcase NAME, failure MESSAGE unless
# OK is 0) and "LABEL NAME: passed (MESSAGE)" or "...: FAILED (MESSAGE)".
junit_result() {
  local dir=$1 suite=$2 label=$3 name=$4 ok=$5 msg=$6 m
  m=$(printf '%s' "$msg" | sed -e 's/&/\&amp;/g' -e 's/</\&lt;/g' -e 's/>/\&gt;/g' -e 's/"/\&quot;/g')
  if [ "$ok" = 0 ]; then
    echo "<testsuite name=\"$suite\"><testcase classname=\"$suite\" name=\"$name\"/></testsuite>" >"$dir/$name.xml"
    echo "$label $name: passed ($msg)"
  else
    echo "<testsuite name=\"$suite\"><testcase classname=\"$suite\" name=\"$name\"><failure message=\"$m\"/></testcase></testsuite>" >"$dir/$name.xml"
    echo "$label $name: FAILED ($msg)"
  fi
}
