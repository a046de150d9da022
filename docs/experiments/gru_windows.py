"""What a cheaper GRU epoch would cost in learning: train the GRU on windows that start every
STRIDE frames instead of every frame (an epoch then runs ~STRIDE times fewer steps), on the
bundled sample; then fly it with eval. Not a feature: a measurement behind
docs/results/defaults.md ("Why a GRU epoch is slow").

    python docs/experiments/gru_windows.py STRIDE EPOCHS OUT
    python -m gymfg_il.eval --policy OUT --episodes 16 --seed 5000
"""

import sys

import torch

from gymfg_il.learning import batches
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.policies.configuration_gru import GRUConfig

STRIDE, EPOCHS, OUT = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
every_window = batches.TensorBatches.__init__


def strided(self, frames, batch_size, device="cpu", seed=0, window=None):
    every_window(self, frames, batch_size, device, seed, window)
    if batch_size != 1024 and STRIDE > 1:  # training batches; validation keeps every window
        first, _ = batches.stretches(frames)
        starts = self.starts.numpy()
        self.starts = self.starts[torch.as_tensor((starts - first[starts]) % STRIDE == 0)]


batches.TensorBatches.__init__ = strided
run = train_bc(TrainConfig(policy=GRUConfig(), epochs=EPOCHS, out=OUT))
print(f"stride {STRIDE}, {EPOCHS} epochs: {run.seconds:.1f} s, val loss {run.val_loss[-1]:.4f}")
