"""One run over several processes: the communicator (MPI through mpi4py, or one process) and the
cut of the grid into slabs. Physics lives above; this package only moves and sums numbers."""
