//! Quality measures: Hausdorff distance, angle statistics, flipped faces, volume/area change.
