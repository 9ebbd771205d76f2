from typing import Any, Mapping, Optional, Sequence

from pandas import DataFrame

__all__ = ["split_bones", "identify", "complete_videos", "reconstruct_mri"]

def split_bones(paths: Sequence[Any], seeds: Sequence[Any], out_dir: Any, *, client: Any = None,
                meshes: bool = True, n_threads: Optional[int] = None, overwrite: bool = False,
                progress: bool = False,
                params: Optional[Mapping[str, Any]] = None) -> DataFrame: ...
def identify(probes: Sequence[Any], gallery: Any, *, client: Any = None, top_k: int = 5,
             labels: Optional[Sequence[Any]] = None, n_partitions: Optional[int] = None,
             n_threads: Optional[int] = None, progress: bool = False) -> DataFrame: ...
def complete_videos(clips: Sequence[Any], masks: Sequence[Any], out_dir: Any, *,
                    client: Any = None, n_threads: Optional[int] = None,
                    overwrite: bool = False, progress: bool = False,
                params: Optional[Mapping[str, Any]] = None) -> DataFrame: ...
def reconstruct_mri(kspaces: Sequence[Any], masks: Sequence[Any], out_dir: Any = None, *,
                    priors: Sequence[str] = ("udct",), client: Any = None,
                    n_threads: Optional[int] = None, overwrite: bool = False,
                    progress: bool = False,
                params: Optional[Mapping[str, Any]] = None) -> DataFrame: ...
