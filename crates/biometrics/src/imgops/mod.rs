//! Generic image operations of the biometrics papers, with the exact conventions of the
//! libraries a user would compare against (OpenCV, scikit-image, SciPy).
//!
//! - [`mask`]: binary-mask geometry (components, hole filling, exact Euclidean distance
//!   transform, disk dilation / erosion / closing, contours, convex hulls).
//! - [`tone`]: 8-bit colour to grey (OpenCV's fixed-point BT.601), histogram equalisation
//!   (OpenCV's `equalizeHist`), and 8-bit resizing (area averaging down, bilinear up).

pub mod mask;
pub mod tone;
