#!/bin/sh
# Two "nodes" on one machine (issue 30): two network namespaces (and hostnames) joined by a
# veth pair, addresses only inside them (10.77.0.1 and .2), one MPI rank in each, MPI's TCP
# transport alone over the veth link. mpirun starts the second node's daemon through a
# launch agent that enters that namespace (--mca plm_rsh_agent, in place of ssh), as it
# would start it on another host.
#   sh two_nodes.sh CASE PATHBENCH MPIEXEC DIR
# veth              ranks.sh tcp over the two nodes: static and dynamic balance give the
#                   one-process image byte for byte; the reports name both nodes
# veth_killed_rank  ranks.sh tcp_killed_rank: the rank on node B SIGKILLed: the run ends within 30 s,
#                   non-zero, with a message naming the lost process, no image
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
# ranks.sh's TCP cases, run from node A over both nodes (one rank a node).
export PB_MPI_ARGS="--hostfile $PWD/hosts --map-by node --mca plm_rsh_agent $PWD/agent.sh"
export PB_TCP_ARGS="--mca btl self,tcp --mca btl_tcp_if_include $net --mca oob_tcp_if_include $net --mca pml ob1 --mca osc ^sm,rdma"
case $case_name in
  veth)
    sh "$here/ranks.sh" tcp "$pb" "$mpiexec" "$PWD/tcp" || fail "ranks.sh tcp over the two nodes failed"
    # Each rank on its own node: the reports name both hosts.
    for balance in static dynamic; do
      grep -q '"pb-node-a"' tcp/$balance.json && grep -q '"pb-node-b"' tcp/$balance.json ||
        fail "2 nodes, --balance $balance: the report does not name both nodes"
    done ;;
  veth_killed_rank)
    sh "$here/ranks.sh" tcp_killed_rank "$pb" "$mpiexec" "$PWD/killed" || fail "ranks.sh tcp_killed_rank over the two nodes failed" ;;
  *) fail "unknown case" ;;
esac
echo "two_nodes.sh $case_name: ok"
