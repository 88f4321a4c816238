#!/bin/sh
# Two "nodes" on one machine (issue 30): two network namespaces (and hostnames) joined by a
# veth pair, addresses only inside them (10.77.0.1 and .2), one MPI rank in each, MPI's TCP
# transport alone over the veth link. mpirun starts the second node's daemon through a
# launch agent that enters that namespace (--mca plm_rsh_agent, in place of ssh), as it
# would start it on another host.
#   sh two_nodes.sh CASE PATHBENCH MPIEXEC DIR
# veth              static and dynamic balance: the one-process image byte for byte
# veth_killed_rank  the rank on the second node SIGKILLed: the run ends within 30 s, non-zero,
#                   with a message naming the lost process, no image
# Skipped (status 77, with the reason) where user and network namespaces or veth links
# cannot be made (unshare -rnu, ip link add ... type veth): e.g. a container without them.
set -u
case_name=$1
pb=$2
mpiexec=$3
dir=$4
here=$(cd "$(dirname "$0")" && pwd)
skip() { echo "two_nodes.sh $case_name: skipped: $*"; exit 77; }
fail() { echo "two_nodes.sh $case_name: $*" >&2; exit 1; }

if [ "${PB_TWO_NODES_INNER:-}" != 1 ]; then
  # Outside: can this machine make the namespaces? Then run this script again inside a user
  # and network namespace of its own (node A: root there, its own hostname).
  for tool in unshare nsenter ip; do
    command -v $tool >/dev/null 2>&1 || skip "no '$tool' here"
  done
  why=$(unshare -rnu sh -c 'ip link add pbv0 type veth peer name pbv1' 2>&1) ||
    skip "cannot make a user and network namespace with a veth link here (unshare -rnu: ${why:-failed})"
  rm -rf "$dir"
  mkdir -p "$dir"
  PB_TWO_NODES_INNER=1 exec unshare -rnu --fork sh "$here/two_nodes.sh" "$@"
fi

# Inside node A's namespaces.
cd "$dir" || exit 1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
hostname pb-node-a || fail "cannot set node A's hostname"
ip link set lo up
# Node B: a process holding a network and UTS namespace of its own.
unshare -nu sh -c 'hostname pb-node-b && ip link set lo up && exec sleep 300' &
node_b=$!
trap 'kill $node_b 2>/dev/null' EXIT
for _ in 1 2 3 4 5 6 7 8 9 10; do
  [ "$(nsenter -t $node_b -u hostname 2>/dev/null)" = pb-node-b ] && break
  sleep 0.2
done
ip link add pbva type veth peer name pbvb netns $node_b || fail "cannot make the veth pair"
ip addr add 10.77.0.1/24 dev pbva && ip link set pbva up || fail "cannot bring node A's link up"
nsenter -t $node_b -n sh -c 'ip addr add 10.77.0.2/24 dev pbvb && ip link set pbvb up' || fail "cannot bring node B's link up"
# The launch agent (ssh's place): `agent [options] HOST COMMAND...` runs COMMAND on node B.
cat > agent.sh <<EOF
#!/bin/sh
while [ \$# -gt 0 ] && [ "\${1#-}" != "\$1" ]; do shift; done
shift  # the host: node B is the only remote one
exec nsenter -t $node_b -n -u -- /bin/sh -c "\$*"
EOF
chmod +x agent.sh
printf '10.77.0.1 slots=1\n10.77.0.2 slots=1\n' > hosts
net=10.77.0.0/24
mpi="$mpiexec --hostfile hosts --map-by node --bind-to none --mca plm_rsh_agent $PWD/agent.sh
     --mca btl self,tcp --mca btl_tcp_if_include $net --mca oob_tcp_if_include $net --mca pml ob1 --mca osc ^sm,rdma"
base="render --quiet --width 64 --height 64 --bounces 2"
frame="$base --spp 24"
film_hash() { grep -o '"film_hash": "[^"]*"' "$1"; }
run() {
  timeout 60 $mpi "$@" >out.txt 2>err.txt
  status=$?
}

case $case_name in
  veth)
    "$pb" $frame --threads 1 --out one.pfm --report one.json || fail "one-process render failed"
    for balance in static dynamic; do
      run -np 2 "$pb" $frame --balance $balance --out $balance.pfm --report $balance.json
      [ "$status" = 0 ] || { cat err.txt >&2; fail "2 nodes, --balance $balance: status $status"; }
      cmp -s one.pfm $balance.pfm || fail "2 nodes, --balance $balance: the image differs from one process's"
      [ "$(film_hash one.json)" = "$(film_hash $balance.json)" ] || fail "2 nodes, --balance $balance: film_hash differs"
      # Each rank on its own node: the report names both hosts.
      grep -q '"pb-node-a"' $balance.json && grep -q '"pb-node-b"' $balance.json ||
        fail "2 nodes, --balance $balance: the report does not name both nodes"
    done ;;
  veth_killed_rank)
    start=$(date +%s)
    run -np 1 "$pb" $base --spp 100000 --out x.pfm : \
        -np 1 sh -c "\"$pb\" $base --spp 100000 --out x.pfm & p=\$!; sleep 2; kill -9 \$p; wait \$p"
    elapsed=$(( $(date +%s) - start ))
    [ "$status" != 0 ] || fail "the run succeeded"
    [ "$status" != 124 ] || fail "the run hung (killed by timeout after 60 s)"
    [ "$elapsed" -le 30 ] || fail "the run took $elapsed s to end"
    grep -q "exited on signal 9\|Exit code: *137\|signal 9" err.txt || { cat err.txt >&2; fail "no word of the killed rank"; }
    [ ! -e x.pfm ] || fail "x.pfm was written"
    ls | grep -q '\.tmp' && fail "a temporary file was left: $(ls)" ;;
  *) fail "unknown case" ;;
esac
echo "two_nodes.sh $case_name: ok"
