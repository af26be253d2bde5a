(function(){
  for (const sec of document.querySelectorAll('section.sfo')) {
    const stage = sec.querySelector('.stage');
    const skull = sec.querySelector('.skull-layer');
    if (!skull) continue;
    const outside = sec.querySelector('.outside-layer');
    const marks = sec.querySelector('.marks');
    const line = sec.querySelector('.wipe-line');
    const opacity = sec.querySelector('input.opacity');
    const wipe = sec.querySelector('input.wipe');
    const showMarks = sec.querySelector('input.show-marks');
    const showOutside = sec.querySelector('input.show-outside');
    function update() {
      skull.style.opacity = String(opacity.value / 100);
      opacity.nextElementSibling.textContent = opacity.value + ' %';
      const clip = 'inset(0px ' + (100 - wipe.value) + '% 0px 0px)';
      skull.style.clipPath = clip;
      if (outside) {
        outside.style.clipPath = clip;
        outside.style.display = showOutside && showOutside.checked ? 'block' : 'none';
      }
      wipe.nextElementSibling.textContent = wipe.value + ' %';
      line.style.left = wipe.value + '%';
      line.hidden = Number(wipe.value) >= 100;
      marks.style.display = showMarks.checked ? 'block' : 'none';
    }
    for (const el of [opacity, wipe, showMarks, showOutside]) {
      if (el) el.addEventListener('input', update);
      if (el) el.addEventListener('change', update);
    }
    let dragging = false;
    function drag(ev) {
      const box = stage.getBoundingClientRect();
      const pct = 100 * (ev.clientX - box.left) / box.width;
      wipe.value = String(Math.round(Math.min(100, Math.max(0, pct))));
      update();
    }
    stage.addEventListener('pointerdown', function(ev) {
      dragging = true;
      try { stage.setPointerCapture(ev.pointerId); } catch (err) { /* synthetic event */ }
      drag(ev);
    });
    stage.addEventListener('pointermove', function(ev) { if (dragging) drag(ev); });
    stage.addEventListener('pointerup', function() { dragging = false; });
    update();
  }
})();
