// Time: play and pause (space), a slider over the recorded frames, speed,
// one frame back or on (arrow keys), and the instant where cairn and
// Bullet part marked on the slider in red. Playback follows the wall clock
// times the speed and loops at the end.
'use strict';
var CairnViewer = CairnViewer || {};

(function (V) {
  V.Timeline = function (replay) {
    this.replay = replay;
    this.time = 0;
    this.playing = false;
    this.speed = 1;
    this.play = document.getElementById('play');
    this.slider = document.getElementById('slider');
    this.clock = document.getElementById('clock');
    this.slider.max = String(Math.max(0, replay.frames - 1));
    this.play.onclick = () => this.setPlaying(!this.playing);
    document.getElementById('back').onclick = () => this.step(-1);
    document.getElementById('forward').onclick = () => this.step(1);
    const speed = document.getElementById('speed');
    speed.onchange = () => { this.speed = Number(speed.value); };
    this.slider.oninput = () => { this.time = replay.cairn.time[Number(this.slider.value)]; };
    document.addEventListener('keydown', (e) => {
      // The speed list and the focused slider handle their own keys.
      if (e.target.tagName === 'SELECT' || (e.target === this.slider && e.key !== ' ')) return;
      if (e.key === ' ') { this.setPlaying(!this.playing); e.preventDefault(); }
      else if (e.key === 'ArrowLeft') { this.step(-1); e.preventDefault(); }
      else if (e.key === 'ArrowRight') { this.step(1); e.preventDefault(); }
      else if (e.key === 'Home') this.seek(0);
    });
    const p = replay.parting;
    if (p && p.frame >= 0 && replay.frames > 1) {
      const mark = document.getElementById('parting');
      const fraction = p.frame / (replay.frames - 1);
      // The range thumb is about 16 px wide: its center runs from 8 px to width - 8 px.
      mark.style.left = 'calc(8px + (100% - 16px) * ' + fraction + ')';
      mark.title = 'cairn and Bullet part here: t = ' + p.time.toFixed(3) + ' s, body \'' +
        replay.bodies[p.body].name + '\' ' + p.distance.toFixed(3) + ' m apart (tolerance ' + p.tolerance + ' m)';
      mark.hidden = false;
    }
  };

  V.Timeline.prototype.setPlaying = function (on) {
    if (on && this.frame() === this.replay.frames - 1) this.time = 0;
    this.playing = on;
    this.play.innerHTML = on ? '&#10074;&#10074;' : '&#9654;';
  };

  V.Timeline.prototype.frame = function () { return V.frameAt(this.replay, this.time); };

  V.Timeline.prototype.seek = function (t) { this.time = Math.min(Math.max(t, 0), this.replay.duration); };

  V.Timeline.prototype.step = function (df) {
    this.setPlaying(false);
    const f = Math.min(Math.max(this.frame() + df, 0), this.replay.frames - 1);
    this.time = this.replay.cairn.time[f];
  };

  // Advances by `seconds` of wall time; returns the frame to show.
  V.Timeline.prototype.advance = function (seconds) {
    if (this.playing) {
      this.time += seconds * this.speed;
      if (this.time > this.replay.duration) this.time = 0;
    }
    const f = this.frame();
    this.slider.value = String(f);
    this.clock.textContent = 't = ' + this.replay.cairn.time[f].toFixed(3) + ' s  frame ' + f + '/' + (this.replay.frames - 1);
    return f;
  };
})(CairnViewer);
