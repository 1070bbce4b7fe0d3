"""The native backend measured per OpenMM platform: its time per step against OpenMM's VerletIntegrator and the
CustomIntegrator program (:mod:`.speed`, ``symprk speed``), momentum conservation with and without exact-momentum
projection (:mod:`.conservation`, ``symprk conservation``), and both with the two backends' agreement on CUDA
(:mod:`.gpucheck`, ``symprk gpucheck``)."""
