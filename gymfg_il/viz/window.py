"""A window that shows camera frames (gymnasium's ``render_mode="human"``), paced to real time."""

from __future__ import annotations

from typing import Any

import numpy as np


class FrameWindow:
    """A pygame window showing RGB frames scaled to ``size``, at most ``fps`` frames a second
    (the simulation then runs at real time, as a person watching expects)."""

    def __init__(
        self, size: tuple[int, int] = (512, 512), fps: float = 10.0, title: str = "GymFG"
    ) -> None:
        import pygame

        self.pg: Any = pygame
        pygame.display.init()
        self.screen = pygame.display.set_mode(size)
        pygame.display.set_caption(title)
        self.size, self.fps = size, fps
        self.clock = pygame.time.Clock()

    def show(self, frame: np.ndarray) -> None:
        pg = self.pg
        pg.event.pump()  # a window that is not pumped is "not responding"
        surface = pg.image.frombuffer(
            np.ascontiguousarray(frame).tobytes(), frame.shape[1::-1], "RGB"
        )
        self.screen.blit(pg.transform.scale(surface, self.size), (0, 0))
        pg.display.flip()
        self.clock.tick(self.fps)

    def close(self) -> None:
        self.pg.display.quit()
