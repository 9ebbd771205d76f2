from dataclasses import dataclass
from typing import List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np

__all__ = ["render_kernel", "kernel_grid", "blurriness", "deconv_krishnan",
           "deconv_krishnan_multi", "wiener", "richardson_lucy", "convolve",
           "deblur_piecewise", "deblur_multiframe", "rectify_rolling_shutter",
           "phase_correlation", "estimate_time_delay", "w_step", "make_gyro", "add_gyro_noise",
           "render_blurred", "make_scene", "METHODS", "MultiframeDeblur", "estimate_noise"]

_Lam = Union[float, Literal["auto"]]

METHODS: Tuple[str, ...]

@dataclass(frozen=True)
class MultiframeDeblur:
    image: np.ndarray
    single: np.ndarray
    weights: np.ndarray
    used_frames: List[int]
    warnings: List[str]
    kernels: np.ndarray

def render_kernel(gyro: np.ndarray, t_frame: float, t_exposure: float, f: float, cx: float,
                  cy: float, x: float, y: float, t_readout: float = ..., t_delay: float = ...,
                  height: Optional[int] = ..., r_cam_imu: Optional[np.ndarray] = ...,
                  bias: Optional[Sequence[float]] = ...) -> Tuple[np.ndarray, Tuple[int, int]]: ...
def kernel_grid(gyro: np.ndarray, t_frame: float, t_exposure: float, f: float, cx: float,
                cy: float, height: int, width: int, tile: int = ..., t_readout: float = ...,
                t_delay: float = ..., r_cam_imu: Optional[np.ndarray] = ...,
                bias: Optional[Sequence[float]] = ...) -> np.ndarray: ...
def blurriness(kernel: np.ndarray, origin: Optional[Tuple[int, int]] = ...) -> float: ...
def estimate_noise(image: np.ndarray) -> float: ...
def deconv_krishnan(image: np.ndarray, kernel: np.ndarray, origin: Optional[Tuple[int, int]] = ...,
                    lam: _Lam = ..., alpha: float = ..., beta_max: float = ...) -> np.ndarray: ...
def deconv_krishnan_multi(image: np.ndarray, kernel: np.ndarray, prior: np.ndarray,
                          mu: float = ..., origin: Optional[Tuple[int, int]] = ...,
                          lam: _Lam = ..., alpha: float = ...,
                          beta_max: float = ...) -> np.ndarray: ...
def wiener(image: np.ndarray, kernel: np.ndarray, origin: Optional[Tuple[int, int]] = ...,
           nsr: float = ...) -> np.ndarray: ...
def richardson_lucy(image: np.ndarray, kernel: np.ndarray,
                    origin: Optional[Tuple[int, int]] = ..., n_iter: int = ...) -> np.ndarray: ...
def convolve(image: np.ndarray, kernel: np.ndarray,
             origin: Optional[Tuple[int, int]] = ...) -> np.ndarray: ...
@overload
def deblur_piecewise(frame: np.ndarray, gyro: np.ndarray, t_frame: float, t_exposure: float,
                     f: float, cx: float, cy: float, t_readout: float = ..., t_delay: float = ...,
                     method: str = ..., tile: int = ..., lam: _Lam = ..., alpha: float = ...,
                     nsr: float = ..., rl_n_iter: int = ..., r_cam_imu: Optional[np.ndarray] = ...,
                     bias: Optional[Sequence[float]] = ...,
                     return_kernels: Literal[False] = ...) -> np.ndarray: ...
@overload
def deblur_piecewise(frame: np.ndarray, gyro: np.ndarray, t_frame: float, t_exposure: float,
                     f: float, cx: float, cy: float, t_readout: float = ..., t_delay: float = ...,
                     method: str = ..., tile: int = ..., lam: _Lam = ..., alpha: float = ...,
                     nsr: float = ..., rl_n_iter: int = ..., r_cam_imu: Optional[np.ndarray] = ...,
                     bias: Optional[Sequence[float]] = ..., *,
                     return_kernels: Literal[True]) -> Tuple[np.ndarray, np.ndarray]: ...
def deblur_multiframe(frames: Sequence[np.ndarray], frame_times: Sequence[float],
                      gyro: np.ndarray, f: float, cx: float, cy: float, t_exposure: float,
                      t_readout: float = ..., t_delay: float = ..., main: Optional[int] = ...,
                      mu: float = ..., lam: _Lam = ..., alpha: float = ...,
                      gamma: Optional[float] = ..., align: str = ..., min_ncc: float = ...,
                      temporal_radius: Optional[int] = ..., tile: int = ...,
                      r_cam_imu: Optional[np.ndarray] = ...,
                      bias: Optional[Sequence[float]] = ...) -> MultiframeDeblur: ...
def rectify_rolling_shutter(frame: np.ndarray, gyro: np.ndarray, t_frame: float,
                            t_exposure: float, t_readout: float, t_delay: float, f: float,
                            cx: float, cy: float, r_cam_imu: Optional[np.ndarray] = ...,
                            bias: Optional[Sequence[float]] = ...) -> np.ndarray: ...
def phase_correlation(a: np.ndarray, b: np.ndarray) -> Tuple[float, float]: ...
def estimate_time_delay(gyro: np.ndarray, frame_times: Sequence[float], shifts: np.ndarray,
                        t_exposure: float, t_readout: float, f: float, cx: float, cy: float,
                        lo: float, hi: float, step: float = ...,
                        r_cam_imu: Optional[np.ndarray] = ...,
                        bias: Optional[Sequence[float]] = ...) -> float: ...
def w_step(v: Union[np.ndarray, Sequence[float], float], alpha: float,
           beta: float) -> np.ndarray: ...

def make_gyro(duration: float, rate: float = ..., tau: float = ...,
              std: Sequence[float] = ..., t0: float = ..., seed: int = ...) -> np.ndarray: ...
def add_gyro_noise(gyro: np.ndarray, sigma: float = ..., seed: int = ...) -> np.ndarray: ...
def render_blurred(sharp: np.ndarray, gyro: np.ndarray, t_frame: float, t_exposure: float,
                   f: float, cx: float, cy: float, t_world: float, t_readout: float = ...,
                   t_delay: float = ..., noise_sigma: float = ...,
                   gamma: Optional[float] = ..., quantise: bool = ..., seed: int = ...,
                   r_cam_imu: Optional[np.ndarray] = ...,
                   bias: Optional[Sequence[float]] = ...) -> np.ndarray: ...
def make_scene(height: int, width: int, seed: int = ...) -> np.ndarray: ...
