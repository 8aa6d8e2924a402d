# Sourced by the dev scripts that start a ROS master and nodes themselves:
# they wait for readiness, never for a fixed time, so a loaded machine only
# makes them slower.
#   wait_until WHAT SECONDS COMMAND...   until COMMAND succeeds; past SECONDS
#                                        prints "<script>: WHAT not ready"
#                                        and exits 1
#   node_up NAME                         a node whose name contains NAME is
#                                        registered with the master

wait_until() {
  local what=$1 end=$((SECONDS + $2)) limit=$2
  shift 2
  until "$@" >/dev/null 2>&1; do
    if [ $SECONDS -ge $end ]; then
      echo "$(basename "$0"): $what not ready after ${limit} s"
      exit 1
    fi
    sleep 0.2
  done
}

node_up() { rosnode list 2>/dev/null | grep -q "$1"; }
