/** Live frames: press first, release last, one frame per animation frame at most fps. */
import { describe, expect, it } from "vitest";
import { FrameSampler } from "../src/frame-sampler";

const at = (t_ms: number, x = 0, y = 0) => ({ t_ms, x, y, pressure: 0.5 });

describe("FrameSampler", () => {
  it("takes the press as the first frame and holds the latest reading at each frame", () => {
    const sampler = new FrameSampler(60);
    expect(sampler.tick(5)).toBeNull(); // not pressed
    expect(sampler.press(at(100, 1, 1))).toEqual(at(100, 1, 1));
    sampler.hold(at(104, 2, 2));
    sampler.hold(at(110, 3, 3));
    expect(sampler.tick(116.7)).toEqual(at(116.7, 3, 3));
  });

  it("at 60 fps on a 60 Hz display takes every animation frame, jitter and all", () => {
    const sampler = new FrameSampler(60);
    sampler.press(at(0));
    const times = [16.9, 33.2, 50.1, 66.5, 83.4];
    expect(times.map((t) => sampler.tick(t) !== null)).toEqual([true, true, true, true, true]);
  });

  it("at 30 fps takes every other animation frame", () => {
    const sampler = new FrameSampler(30);
    sampler.press(at(0));
    const taken = [16.7, 33.3, 50, 66.7, 83.3, 100].filter((t) => sampler.tick(t) !== null);
    expect(taken).toEqual([33.3, 66.7, 100]);
  });

  it("the release is the last frame and never earlier than the frame before it", () => {
    const sampler = new FrameSampler(60);
    sampler.press(at(0));
    sampler.tick(16.7);
    expect(sampler.release(at(15, 9, 9))).toEqual(at(16.7, 9, 9));
    expect(sampler.pressed).toBe(false);
    expect(sampler.tick(40)).toBeNull();
  });
});
