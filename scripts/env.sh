# Source me: the environment every ardsim command runs in (Debian's ROS 1 under /usr, the workspace's devel space).
ARDSIM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# The catkin setup and profile hooks read unset variables: source them without `set -u`, then restore it.
case $- in *u*) ardsim_nounset=1; set +u ;; *) ardsim_nounset=0 ;; esac
export PATH=/usr/bin:$PATH   # a pyenv python3 earlier on PATH hides Debian's python3 and its ROS modules
if [ -f "$ARDSIM_ROOT/devel/setup.bash" ]; then
  # shellcheck disable=SC1091
  . "$ARDSIM_ROOT/devel/setup.bash"
else
  for f in /etc/catkin/profile.d/*.sh; do . "$f"; done
fi
export ROS_HOME="${ROS_HOME:-$ARDSIM_ROOT/.ros}"
export ROS_MASTER_URI="${ROS_MASTER_URI:-http://127.0.0.1:11311}" ROS_IP=127.0.0.1
export ROSCONSOLE_STDOUT_LINE_BUFFERED=1
# ccache: one cache for every checkout (CI builds a fresh clone), with paths made relative to the checkout so that
# clones in other directories hit it. Set before XDG_CACHE_HOME moves, or ccache would keep a cache per checkout.
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
export CCACHE_BASEDIR="$ARDSIM_ROOT"
# Mesa, Qt and rviz write caches under $HOME: keep them inside the workspace.
export XDG_CACHE_HOME="${XDG_CACHE_HOME:-$ARDSIM_ROOT/.home/cache}"
mkdir -p "$ROS_HOME" "$XDG_CACHE_HOME"
[ "$ardsim_nounset" = 1 ] && set -u
unset ardsim_nounset
