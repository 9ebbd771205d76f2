"""The naming convention of py/API.md, checked on every public callable of every module.

Each rule below fails on a name the page forbids, so a new function or argument that drifts
from the convention fails here, naming the module, the callable and the rule."""

from __future__ import annotations

import ast
import collections.abc
import dataclasses
import importlib
import inspect
import pathlib
import re
import typing

import pytest

import wscg

MODULES = ["biometrics", "cloth", "csmri", "deblur", "doe", "ear", "gait", "hdr", "isosurface",
           "math", "meshfilter", "motion", "octree", "raytrace", "video", "volren", "volseg",
           "distributed"]

# Parameter names that py/API.md replaces by one name per concept (name -> the name to use).
SYNONYMS = {
    "maxiter": "max_iter", "max_iterations": "max_iter", "max_iters": "max_iter",
    "iters": "n_iter or max_iter", "iterations": "n_iter", "n_iters": "n_iter",
    "niter": "n_iter", "num_iter": "n_iter",
    "tolerance": "tol",
    "random_state": "seed", "rng": "seed", "random_seed": "seed",
    "threads": "n_threads", "num_threads": "n_threads", "n_jobs": "n_threads",
    "workers": "n_threads",
    "components": "n_components", "n_comp": "n_components",
    "neighbors": "n_neighbors", "n_neighbours": "n_neighbors", "k_neighbors": "n_neighbors",
    "knn": "n_neighbors",
    "subjects": "n_subjects",
    "filename": "path", "fname": "path", "file": "path", "out": "path", "output": "path",
    "out_path": "path", "output_dir": "out_dir", "outdir": "out_dir",
    "verbose": "progress", "show_progress": "progress",
    "img": "image", "im": "image",
    "voxel_size": "spacing", "sampling": "spacing",
    "iso": "level", "isovalue": "level",
}
# Suffixes and prefixes of the same synonyms inside longer names (`patchmatch_iters`).
SYNONYM_PATTERNS = [
    (re.compile(r"_iters$"), "<stage>_n_iter or <stage>_max_iter"),
    (re.compile(r"_iterations$"), "<stage>_n_iter or <stage>_max_iter"),
    (re.compile(r"^num_"), "n_<things>"),
    (re.compile(r"_inner$"), "<stage>_n_iter"),
]
# Function names: verbs of py/API.md.
FORBIDDEN_NAMES = [
    (re.compile(r"^read_"), "load_<what>"),
    (re.compile(r"^write_"), "save_<what>"),
    (re.compile(r"^synth"), "make_<what>"),
    (re.compile(r"^generate_"), "make_<what>"),
]

def _public(module):
    """(qualified name, callable) of every public function, class and method of `module`."""
    out = []
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n in dir(module) if not n.startswith("_")]
    for name in names:
        obj = getattr(module, name)
        if inspect.ismodule(obj):
            continue
        if inspect.isclass(obj):
            out.append((f"{module.__name__}.{name}", obj))
            for attr, member in vars(obj).items():
                if attr.startswith("_") and attr != "__init__":
                    continue
                if isinstance(member, (staticmethod, classmethod)):
                    member = member.__func__
                if callable(member):
                    out.append((f"{module.__name__}.{name}.{attr}", member))
        elif callable(obj):
            out.append((f"{module.__name__}.{name}", obj))
    return out


def _signature(obj):
    try:
        return inspect.signature(obj)
    except (TypeError, ValueError):
        return None


def _callables(module):
    """(qualified name, callable) of every public callable of ``wscg.<module>``."""
    return _public(importlib.import_module(f"wscg.{module}"))


def _signatures(module):
    """(qualified name, signature) of the public callables of ``wscg.<module>`` that have
    one."""
    for qual, obj in _callables(module):
        sig = _signature(obj)
        if sig is not None:
            yield qual, sig


@pytest.mark.parametrize("module", MODULES)
def test_no_parameter_synonyms(module):
    bad = []
    for qual, sig in _signatures(module):
        for p in sig.parameters:
            if p in SYNONYMS:
                bad.append(f"{qual}({p}=...): use {SYNONYMS[p]}")
            for pat, use in SYNONYM_PATTERNS:
                if pat.search(p):
                    bad.append(f"{qual}({p}=...): use {use}")
    assert not bad, "parameter names outside py/API.md's table:\n" + "\n".join(sorted(set(bad)))


@pytest.mark.parametrize("module", MODULES)
def test_verbs(module):
    bad = []
    for qual, obj in _callables(module):
        if inspect.isclass(obj):
            continue
        name = qual.rsplit(".", 1)[-1]
        for pat, use in FORBIDDEN_NAMES:
            if pat.search(name):
                bad.append(f"{qual}: use {use}")
        if name in ("synthetic", "phantom") or (name.endswith("_phantom") and not name.startswith("make_")):
            bad.append(f"{qual}: generated data is make_<what>")
        if name.startswith(("load_", "save_")):
            sig = _signature(obj)
            if sig is not None:
                params = [p for p in sig.parameters if p not in ("self", "cls")]
                if not params or params[0] != "path":
                    bad.append(f"{qual}: the path comes first (got {params[:1]})")
    assert not bad, "names outside py/API.md's verbs:\n" + "\n".join(sorted(bad))


@pytest.mark.parametrize("module", MODULES)
def test_no_var_keyword_in_public_signatures(module):
    bad = []
    for qual, sig in _signatures(module):
        for p in sig.parameters.values():
            if p.kind is inspect.Parameter.VAR_KEYWORD:
                bad.append(f"{qual}(**{p.name})")
    assert not bad, "public signatures hide their parameters:\n" + "\n".join(sorted(bad))


@pytest.mark.parametrize("module", MODULES)
def test_all_is_complete(module):
    mod = importlib.import_module(f"wscg.{module}")
    assert hasattr(mod, "__all__"), f"wscg.{module} has no __all__"
    missing = [n for n in mod.__all__ if not hasattr(mod, n)]
    assert not missing, f"wscg.{module}.__all__ names what it does not define: {missing}"
    defined = []
    for n, obj in vars(mod).items():
        if n.startswith("_") or inspect.ismodule(obj):
            continue
        if getattr(obj, "__module__", None) == mod.__name__ and n not in mod.__all__:
            defined.append(n)
    assert not defined, f"wscg.{module} defines public names missing from __all__: {defined}"


def test_top_level_all_lists_every_module():
    missing = [m for m in MODULES if m not in wscg.__all__]
    assert not missing, f"wscg.__all__ lacks {missing}"


# ---------------------------------------------------------------------------------------
# Results (py/API.md, section Results): no public function or method returns a bare dict.

# Annotations that name a mapping: `dict`, `Dict[...]`, `Mapping[...]` (also inside a
# Union, Tuple or Optional), evaluated or written as a string.
_MAPPING_WORDS = re.compile(r"\b(dict|Dict|Mapping|MutableMapping|OrderedDict)\b")
_MAPPING_TYPES = (dict, collections.abc.Mapping, collections.abc.MutableMapping)

# Callables that return a mapping by nature, with the reason; they keep a `dict`.
RESULT_EXCEPTIONS = {
    "get_params": "scikit-learn's protocol: the hyper-parameters by name, for set_params",
    "biometrics.hand_pose_jitter": "a configuration the user edits and passes back as "
                                   "make_hand_poses(jitter=...)",
    "ear.EarMatcher.params": "the keyword parameters the matcher was built with, by name",
    "motion.Synthesizer.planner": "the planner's parameters by name (comfort, gamma, ranges)",
    "volren.orbit_camera": "keyword arguments of the paper-03 render functions "
                           "(client.render(**cam)), also passed as size_report(thin_client_view=)",
    "raytrace.ManyLightScene.camera": "the camera as the dict that camera= of "
                                      "render_manylight takes back, entries edited by name",
}


def _names_mapping(annotation) -> bool:
    if annotation is inspect.Signature.empty or annotation is None:
        return False
    if isinstance(annotation, str):
        return bool(_MAPPING_WORDS.search(annotation))
    if isinstance(annotation, type) and issubclass(annotation, _MAPPING_TYPES):
        return True
    origin = typing.get_origin(annotation)
    if isinstance(origin, type) and issubclass(origin, _MAPPING_TYPES):
        return True
    return any(_names_mapping(a) for a in typing.get_args(annotation))


def _excepted(qual: str) -> bool:
    short = qual.split(".", 1)[1]
    return short in RESULT_EXCEPTIONS or short.rsplit(".", 1)[-1] in RESULT_EXCEPTIONS


def _stub_returns(mod):
    """(qualified name, return annotation as written) of the public functions, methods and
    properties of the stub file next to ``mod`` (the annotations type checkers see; native
    methods have none at run time)."""
    path = pathlib.Path(mod.__file__).with_suffix(".pyi")
    if not path.exists():
        return []
    tree = ast.parse(path.read_text())
    out = []

    def walk(body, prefix):
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                if node.returns is not None and not node.name.startswith("_"):
                    out.append((f"{prefix}.{node.name}", ast.unparse(node.returns)))
            elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                walk(node.body, f"{prefix}.{node.name}")

    walk(tree.body, mod.__name__)
    return out


@pytest.mark.parametrize("module", MODULES)
def test_no_function_returns_a_dict(module):
    bad = []
    mod = importlib.import_module(f"wscg.{module}")
    for qual, ann in _stub_returns(mod):
        if not _excepted(qual) and _names_mapping(ann):
            bad.append(f"{qual} -> {ann} (stub)")
    for qual, obj in _public(mod):
        if _excepted(qual):
            continue
        members = [(qual, obj)]
        if inspect.isclass(obj):
            # Properties: the annotation of the getter.
            members = [(f"{qual}.{a}", p.fget) for a, p in vars(obj).items()
                       if isinstance(p, property) and not a.startswith("_")
                       and not _excepted(f"{qual}.{a}")]
        for name, fn in members:
            sig = _signature(fn)
            if sig is not None and _names_mapping(sig.return_annotation):
                bad.append(f"{name} -> {sig.return_annotation}")
    assert not bad, ("functions annotated to return a mapping (py/API.md wants a result "
                     "class):\n" + "\n".join(sorted(bad)))


# Every function converted from a dict to a result class, with the class its annotation
# names: the check above cannot see a function without an annotation.
CONVERTED = {
    "biometrics.feature_kernel": "ResolvedKernel",
    "biometrics.hand_pose_split": "HandPoseSplit",
    "biometrics.hand_pose_comparison": "HandPoseComparison",
    "ear.detect_occlusion": "OcclusionReport",
    "ear.EarMatcher.identify": "Identification",
    "ear.EarMatcher.identify_baseline": "Ranking",
    "ear.score": "MatchScore",
    "ear.make_ears": "EarDataset",
    "ear.evaluate": "EarEvaluation",
    "gait.detect_cycle": "CycleDetails",
    "gait.make_walkers": "SyntheticWalks",
    "gait.load_ntu_bodies": "NtuBody",
    "gait.evaluate_synthetic": "GaitEvaluation",
    "motion.make_synthetic_dataset": "MotionDataset",
    "motion.plan_steps": "StepPlan",
    "motion.Synthesizer.plan": "StepPlan",
    "motion.Synthesizer.run": "Synthesis",
    "motion.load_bvh": "BvhMotion",
    "motion.load_bvh_skeleton": "BvhSkeleton",
    "motion.skeleton": "Skeleton",
    "motion.fit_line": "LineFit",
    "motion.svr_fit_predict": "SvrInfo",
    "motion.hopf_simulate": "HopfTrajectory",
    "hdr.multiscopic_hdr": "HdrSequence",
    "hdr.calibrate_mitsunaga_nayar": "PolynomialResponse",
    "hdr.make_scene": "HdrScene",
    "deblur.deblur_multiframe": "MultiframeDeblur",
    "video.complete_video": "CompletionStats",
    "doe.fit_rsm": "RsmFit",
    "doe.fit_rsm_blocked": "RsmFit",
    "doe.rm_anova": "AnovaTable",
    "doe.rm_anova_oneway": "AnovaEffect",
    "doe.lsd": "LeastSignificantDifference",
    "math.cg": "CgInfo",
    "math.solve_cg": "CgInfo",
    "math.load_mesh": "Mesh",
    "math.load_exif": "ExifInfo",
    "volseg.random_walker_bone": "SolveReport",
    "volseg.RandomWalkerSession.solve": "SolveReport",
    "volseg.RandomWalkerSession.report": "SolveReport",
    "isosurface.marching_cubes": "MeshInfo",
    "isosurface.estimate_normals": "NormalStats",
    "isosurface.angular_rms": "AngularRms",
    "isosurface.study_full_cd": "SparseComparison",
    "isosurface.study_exact": "ExactComparison",
    "volren.HybridServer.size_report": "SizeReport",
    "volren.study": "IlluminationStudy",
    "octree.HybridOctree.memory_report": "MemoryReport",
    "octree.HybridOctree.intersect": "RayHits",
    "octree.HybridOctree.render": "RenderStats",
    "csmri.reconstruct": "ReconstructionHistory",
    "csmri.fcsa": "ReconstructionHistory",
    "csmri.tvcmri": "ReconstructionHistory",
    "csmri.watmri": "ReconstructionHistory",
    "raytrace.render_plate": "PlateInfo",
    "raytrace.glint_stats": "GlintStats",
    "raytrace.workshop": "WorkshopScores",
    "raytrace.render_manylight": "ManyLightStats",
    "cloth.Sim.energy": "Energy",
}


@pytest.mark.parametrize("qual", sorted(CONVERTED))
def test_converted_functions_name_their_result_class(qual):
    module, *path = qual.split(".")
    mod = importlib.import_module(f"wscg.{module}")
    obj = mod
    for p in path:
        obj = getattr(obj, p)
    cls_name = CONVERTED[qual]
    cls = getattr(mod, cls_name)
    assert cls_name in mod.__all__, f"wscg.{module}.{cls_name} is not exported"
    assert cls.__doc__ and "Attributes" in cls.__doc__, f"{cls_name} documents no fields"
    ann = inspect.signature(obj).return_annotation
    text = ann if isinstance(ann, str) else repr(ann)
    assert re.search(rf"\b{cls_name}\b", text), f"{qual} is annotated {text!r}"
    # Every field is documented (with its unit or shape) in the class docstring.
    fields = (cls._fields if hasattr(cls, "_fields")
              else [f.name for f in dataclasses.fields(cls)])
    undocumented = [f for f in fields if not re.search(rf"^\s*[\w, ]*\b{f}\b[\w, ]* :",
                                                        cls.__doc__, re.M)]
    assert not undocumented, f"{cls_name} does not document {undocumented}"


def _stub_parameters(node):
    """Parameter names (without self/cls) and defaults as written of a stub function."""
    a = node.args
    positional = a.posonlyargs + a.args
    names = [x.arg for x in positional] + ([a.vararg.arg] if a.vararg else [])
    names += [x.arg for x in a.kwonlyargs] + ([a.kwarg.arg] if a.kwarg else [])
    defaults = {x.arg: ast.unparse(v)
                for x, v in zip(positional[len(positional) - len(a.defaults):], a.defaults)}
    defaults.update({x.arg: ast.unparse(v) for x, v in zip(a.kwonlyargs, a.kw_defaults)
                     if v is not None})
    return [n for n in names if n not in ("self", "cls")], defaults


@pytest.mark.parametrize("module", MODULES)
def test_stubs_match_the_signatures(module):
    """The hand-written stub of each module names the parameters the module takes, in its
    order, with its literal defaults (a rename that missed the stub fails here)."""
    mod = importlib.import_module(f"wscg.{module}")
    tree = ast.parse(pathlib.Path(mod.__file__).with_suffix(".pyi").read_text())
    bad = []

    def walk(body, obj, prefix):
        for node in body:
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                cls = getattr(obj, node.name, None)
                if cls is None:
                    bad.append(f"{prefix}.{node.name}: in the stub only")
                else:
                    walk(node.body, cls, f"{prefix}.{node.name}")
            elif isinstance(node, ast.FunctionDef) and (not node.name.startswith("_")
                                                       or node.name == "__init__"):
                if any(isinstance(d, ast.Name) and d.id == "overload"
                       for d in node.decorator_list):
                    continue
                live = getattr(obj, node.name, None)
                if live is None:
                    bad.append(f"{prefix}.{node.name}: in the stub only")
                    continue
                sig = None if isinstance(live, property) else _signature(live)
                if sig is None:
                    continue
                names, defaults = _stub_parameters(node)
                runtime = [p for p in sig.parameters if p not in ("self", "cls")]
                if names != runtime:
                    bad.append(f"{prefix}.{node.name}: stub {names}, module {runtime}")
                    continue
                for p in sig.parameters.values():
                    written = defaults.get(p.name, "...")
                    if written == "..." or p.default is inspect.Parameter.empty:
                        continue
                    try:
                        value = ast.literal_eval(written)
                    except ValueError:
                        continue  # a name (a constant of the module): not compared
                    if value != p.default:
                        bad.append(f"{prefix}.{node.name}({p.name}): stub default {written}, "
                                   f"module {p.default!r}")

    walk(tree.body, mod, module)
    assert not bad, "stubs that disagree with the module:\n" + "\n".join(bad)
