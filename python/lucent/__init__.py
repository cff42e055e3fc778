"""Lucent, a programmable ray tracing engine, from Python.

- Ray queries on numpy arrays: ``TriangleMesh(vertices, indices).intersect(origins,
  directions)`` and ``.occluded(...)``, on the CPU or the GPU.
- The engine's host API: ``Context`` and what it creates (buffers as numpy arrays, the node
  graph, variables, programs of the modules compiled into this extension), and launches.
- The samples: ``render("igi", scene="cornell", size=(512, 512), vpls=64)`` returns an
  (H, W, 4) float32 image; ``samples()`` lists them with their options.
- Processes: ``Context(ranks=Ranks.world())`` and ``render(..., ranks=Ranks.world())``
  spread launches over the ranks of ``mpirun -np N python3 script.py``.
- TEA (the fog sample's random numbers): ``tea(block, key, rounds)``, ``tea_statistics()``
  and ``noise("white" | "gradient" | "spectrum")``, as ``lucent tea`` and ``lucent noise``.
- Images: ``read_image(path)``, ``write_image(path, image)`` and ``compare(reference,
  test)`` (RMSE, relative MSE, PSNR and FLIP, as ``lucent compare``).
- Speed: ``bench_rays("sponza.obj", programs=True)`` measures as ``lucent bench rays --json``
  and returns its document as a dict; ``bench_build``, ``bench_spheres``, ``bench_curves``,
  ``bench_igi``, ``bench_fog`` and ``bench_tea`` do the same for the other benchmarks.

docs/python.md in the repository is the tutorial.
"""

from ._lucent import (  # noqa: F401  (the extension is the whole API)
    ALL_EXCEPTIONS,
    GEOMETRY_FLAG_DISABLE_ANYHIT,
    GEOMETRY_FLAG_NONE,
    MOTION_FLAG_END_VANISH,
    MOTION_FLAG_NONE,
    MOTION_FLAG_START_VANISH,
    RAY_FLAG_CULL_BACK_FACING_TRIANGLES,
    RAY_FLAG_CULL_DISABLED_ANYHIT,
    RAY_FLAG_CULL_ENFORCED_ANYHIT,
    RAY_FLAG_CULL_FRONT_FACING_TRIANGLES,
    RAY_FLAG_DISABLE_ANYHIT,
    RAY_FLAG_DISABLE_CLOSESTHIT,
    CURVE_CATMULL_ROM,
    CURVE_CUBIC_BSPLINE,
    CURVE_LINEAR,
    CURVE_QUADRATIC_BSPLINE,
    RAY_FLAG_ENFORCE_ANYHIT,
    RAY_FLAG_NONE,
    RAY_FLAG_TERMINATE_ON_FIRST_HIT,
    VISIBILITY_MASK_ALL,
    Acceleration,
    Buffer,
    Context,
    Error,
    Geometry,
    GeometryBase,
    GeometryCurves,
    GeometryGroup,
    GeometryInstance,
    GeometrySpheres,
    GeometryTriangles,
    Group,
    LaunchReport,
    MappedBuffer,
    Material,
    ModuleInfo,
    Node,
    NodeWithChildren,
    Program,
    RankError,
    Ranks,
    RayHits,
    Selector,
    TextureSampler,
    Transform,
    TriangleMesh,
    __version__,
    bench_build,
    bench_curves,
    bench_fog,
    bench_igi,
    bench_rays,
    bench_spheres,
    bench_tea,
    compare,
    cuda_built,
    modules,
    noise,
    read_image,
    render,
    samples,
    tea,
    tea_statistics,
    types,
    write_image,
)
